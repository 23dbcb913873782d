#pragma once
// the participating media of one frame (EffectsFrame::homogeneous_media and grid_media) in
// the form both render tiers trace: coefficients at a point, closed-form optical depth of the
// homogeneous (optionally height-falloff, optionally boxed) media, trilinear voxel grids,
// ratio-tracked transmittance and spectral delta tracking of free flights.
//
// model (Pharr, Jakob, Humphreys, "Physically Based Rendering", 4th ed., ch. 11 and 14):
// sigma_t = sigma_a + sigma_s per rgb channel; media add where they overlap; a grid's
// emission (EffectsFrame: radiance per unit length) is added along the ray as emission ds.
//
// unbiased estimators (pathtraced tier):
//  - free-flight sampling: the combined majorant process is the superposition of one
//    Poisson process per medium: homogeneous media with rate max_c(sigma_t,c) h(z) (h the
//    height-falloff density, sampled exactly by inverting its closed-form integral) and grids
//    with the constant rate max_c(sigma_t,c) max_density inside their box (delta tracking,
//    Woodcock et al. 1965). the first tentative collision is the earliest of the per-medium
//    samples (memoryless, so every medium is resampled from each collision).
//  - at a tentative collision: absorption / real scattering / null collision are chosen with
//    the history-aware probabilities of spectral tracking (Kutz, Habel, Li, Novak, "Spectral
//    and decomposition tracking for rendering heterogeneous volumes", SIGGRAPH 2017, sec. 5.2:
//    P_x proportional to the channel mean of beta * sigma_x), and the throughput is weighted
//    by sigma_x / (sigma_bar P_x) per channel; emission adds beta * emission / sigma_bar at
//    every tentative collision (PBR 4th ed., sec. 14.2.2).
//  - transmittance: exact exp(-tau) for homogeneous media times ratio tracking (Novak, Selle,
//    Jarosz, "Residual ratio tracking for estimating attenuation in participating media",
//    SIGGRAPH Asia 2014, sec. 3) inside every grid box.
//
// the formulas are the PB_HOST_DEVICE functions of render/media/media_scene_math.h over View(): the
// members below call them, and the CUDA backend's pathtraced tier calls the same ones.

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "penumbra/core/rng.h"
#include "penumbra/render/media/media_realtime_math.h"
#include "penumbra/render/media/media_scene_math.h"
#include "penumbra/scene/effects_frame.h"

namespace penumbra {

/// a HomogeneousMedium prepared for tracing.
struct AnalyticMedium {
  Eigen::Vector3f sigma_t{0, 0, 0};  ///< 1/m at full density
  Eigen::Vector3f sigma_s{0, 0, 0};  ///< sigma_t * albedo, 1/m
  float g = 0;                       ///< Henyey-Greenstein asymmetry
  float falloff = 0;                 ///< height falloff k, 1/m (0 = uniform)
  float base = 0;                    ///< world z below which the density is 1
  /// confined to the box [box_min, box_max]; a layer (HomogeneousMedium::layer_top_m) is the
  /// box with infinite x, y and lower z bounds.
  bool bounded = false;
  Eigen::Vector3f box_min{0, 0, 0}, box_max{0, 0, 0};
  float sigma_bar = 0;  ///< majorant rate at full density: max channel of sigma_t

  /// relative density h(z) = exp(-falloff max(0, z - base)) in (0, 1] (MediumHeightDensity).
  float Density(float z) const { return MediumHeightDensity(falloff, base, z); }
  /// the part [a, b] of [t0, t1] where o + t d is inside the medium; false if empty.
  bool Interval(const Eigen::Vector3f& o, const Eigen::Vector3f& d, float t0, float t1, float* a,
                float* b) const;
  /// integral of h(z(t)) dt over [a, b] for z(t) = oz + dz t (d unit); b may be +inf (then
  /// +inf unless the density vanishes upwards). closed form per piece (below / above base).
  double DensityIntegral(double oz, double dz, double a, double b) const;
  /// the t in [a, b] at which the integral of h from a reaches tau, or +inf if it does not
  /// (inverse of DensityIntegral, closed form).
  double InvertDensityIntegral(double oz, double dz, double a, double b, double tau) const;
};

/// medium m as the shared formulas of render/media/media_realtime_math.h read it (h_cam 1: set it
/// for a camera's height).
MediumPod PodOf(const AnalyticMedium& m);

/// a GridMedium prepared for tracing (the frame's density arrays are shared, not copied).
struct GridVolume {
  Eigen::Matrix3f R_GW = Eigen::Matrix3f::Identity();  ///< rotation world -> grid frame
  Eigen::Vector3f p_GW{0, 0, 0};                       ///< x_G = R_GW x_W + p_GW
  Eigen::Vector3f half{0.5f, 0.5f, 0.5f};              ///< box half extents, m
  int nx = 0, ny = 0, nz = 0;
  Eigen::Vector3f voxels_per_m{1, 1, 1};               ///< n / (2 half) per axis
  std::shared_ptr<const std::vector<float>> density;   ///< (nz x ny x nx)
  std::shared_ptr<const std::vector<float>> emission;  ///< (nz x ny x nx x 3) or null
  Eigen::Vector3f sigma_t{1, 1, 1};                    ///< 1/m at density 1
  Eigen::Vector3f sigma_s{0.9f, 0.9f, 0.9f};           ///< sigma_t * albedo
  float g = 0;
  float max_density = 0;  ///< largest voxel value (recomputed from the data)
  float majorant = 0;     ///< max channel of sigma_t * max_density (> 0 when emissive), 1/m
  /// these fields as the shared functions read them (MediaScene::Build sets it; its arrays
  /// point into density / emission).
  MediaGridPod pod;

  Eigen::Vector3f ToGrid(const Eigen::Vector3f& p_W) const { return R_GW * p_W + p_GW; }
  /// trilinear density at grid-frame point x_G (clamped to the outermost voxel centres inside
  /// the box, 0 outside it).
  float DensityAt(const Eigen::Vector3f& x_G) const;
  /// the voxel-centre cell around x_G: lower/upper voxel indices per axis and the trilinear
  /// weights of the upper ones; false outside the box.
  bool TrilinearCell(const Eigen::Vector3f& x_G, int i0[3], int i1[3], float w[3]) const;
  /// trilinear emission (cd/m^2 per m) at x_G, 0 outside the box or without emission.
  Eigen::Vector3f EmissionAt(const Eigen::Vector3f& x_G) const;
  /// the part [a, b] of [t0, t1] where o + t d (world) is inside the box; false if empty.
  bool Interval(const Eigen::Vector3f& o, const Eigen::Vector3f& d, float t0, float t1, float* a,
                float* b) const;
};

/// coefficients of all media at one point (sigma_t, sigma_s, emission, the majorant rate
/// sigma_bar), with the mixture of their phase functions (MediumPointPod's fields).
struct MediumPoint : MediumPointPod {
  static constexpr int kMaxLobes = kMediumMaxLobes;

  /// the mixture phase function sum_i w_i HG(cos_theta, g_i) / sum_i w_i (MediaPhase).
  float Phase(float cos_theta) const { return MediaPhase(*this, cos_theta); }
  /// samples a lobe with u0, then wi from it; pdf = Phase(dot(wo, wi)) (MediaSamplePhase).
  Eigen::Vector3f SamplePhase(const Eigen::Vector3f& wo, float u0, float u1, float u2,
                              float* pdf) const;
};

// TrackEvent (the outcome of MediaScene::Track): render/media_scene_math.h.

/// the media of one frame. Build once per frame; the queries are thread-safe.
class MediaScene {
 public:
  /// prepares the media of `fx` (null = none).
  /// @throws ConfigError for a grid whose arrays do not match nx ny nz, non-positive half
  /// extents, or negative / non-finite coefficients (key effects.grid_media[i].* or
  /// effects.homogeneous_media[i].*).
  void Build(const EffectsFrame* fx);

  bool empty() const { return analytic_.empty() && grids_.empty(); }
  const std::vector<AnalyticMedium>& analytic() const { return analytic_; }
  /// analytic() as the shared formulas read them (PodOf, same order).
  const std::vector<MediumPod>& analytic_pods() const { return pods_; }
  const std::vector<GridVolume>& grids() const { return grids_; }
  /// the media as the shared functions of render/media/media_scene_math.h read them: pointers into
  /// this object's arrays (valid until the next Build).
  MediaSceneView View() const;

  /// rgb optical depth of the homogeneous media along o + t d (d unit), t in [t0, t1] (t1 may
  /// be +inf). closed form (AnalyticOpticalDepthOf of media_realtime_math.h).
  Eigen::Vector3f AnalyticOpticalDepth(const Eigen::Vector3f& o, const Eigen::Vector3f& d, float t0,
                                       float t1) const;

  /// all coefficients at p_W.
  MediumPoint At(const Eigen::Vector3f& p_W) const;

  /// unbiased transmittance estimate along o + t d (d unit), t in [t0, t1]: exact for the
  /// homogeneous media, ratio tracking in the grids (draws from rng only inside grid boxes).
  Eigen::Vector3f Transmittance(const Eigen::Vector3f& o, const Eigen::Vector3f& d, float t0,
                                float t1, Rng* rng) const;

  /// spectral delta tracking along o + t d (d unit) from t0 to t1 (may be +inf): adds the
  /// emission gathered to *L (times *beta), updates *beta, and on kScatter writes the
  /// collision distance *t and the medium there *mp (its sigma_s already folded into *beta).
  TrackEvent Track(const Eigen::Vector3f& o, const Eigen::Vector3f& d, float t0, float t1, Rng* rng,
                   Eigen::Vector3f* beta, Eigen::Vector3f* L, float* t, MediumPoint* mp) const;

 private:
  std::vector<AnalyticMedium> analytic_;
  std::vector<MediumPod> pods_;
  std::vector<MediumTracePod> terms_;  // per analytic medium: g, sigma_bar
  std::vector<GridVolume> grids_;
  std::vector<MediaGridPod> grid_pods_;  // grids_[i].pod
};

}  // namespace penumbra
