#pragma once
// participating media in the `realtime` tier: single scattering along the camera ray, with
// per-frame precomputed light volumes instead of shadow rays per step.
//
// per frame (Build):
//  - every grid medium gets a coarse light volume (at most kGridLightRes^3 cells on its box):
//    per light j the transmittance T_j through the grid from the cell centre to the light
//    (midpoint-rule march of the full-resolution density, one step per coarse cell), and an
//    isotropic in-scatter source S = sum_j E_j V_j T_j Th_j / (4 pi) + L_sky, with V_j one
//    shadow ray per cell and light and Th_j the homogeneous media's transmittance to the
//    light. the grid's own phase function is treated as isotropic in this tier.
//  - homogeneous media get a world-aligned visibility volume (at most kFogCells cells) over
//    the scene's bounding box (SceneDescription::center_W, extent_m) clipped to the media
//    boxes: per light V_j Th_j T_grid,j (channel mean). beyond it lights are unshadowed.
// per camera ray (IntegrateView), over [0, t_end] (t_end = surface distance or +inf):
//  - homogeneous media: closed-form transmittance (media_scene.h); the sky in-scatter
//    albedo (1 - T) L_sky in closed form, with L_sky the sphere-average sky radiance treated
//    as an isotropic source that reaches every point of the medium unoccluded and
//    unattenuated (Koschmieder's setting; the sky is not shadowed by walls in this tier);
//    light in-scatter from kFogLightSamples stratified distances drawn in proportion to
//    sigma_t T (one lobe of a one-sample mixture per medium), each summing over the lights
//    p_HG(theta) E_j times the visibility volume.
//  - grid media: the ray's overlap with the box is marched in at most kMaxGridSteps jittered
//    steps (step >= one coarse cell); each step adds T (sigma_s S + emission) (1 - e^-x) /
//    sigma_t with exact per-step transmittance e^-x, x = sigma_t ds.
//  - homogeneous in-scatter behind a grid is attenuated by the grid's full transmittance,
//    grid in-scatter by the homogeneous transmittance at the middle of the grid overlap.
// surfaces: each light's contribution is multiplied by LightTransmittance (closed form for
// the homogeneous media, the light volume looked up at the shadow ray's entry into a grid).
// random numbers: the caller's Rng (the pixel's stream), deterministic per pixel.

#include <Eigen/Core>
#include <vector>

#include "penumbra/core/rng.h"
#include "penumbra/core/thread_pool.h"
#include "penumbra/render/light_sampler.h"
#include "penumbra/render/media_scene.h"
#include "penumbra/render/ray_scene.h"

namespace penumbra {

/// largest light-volume resolution per axis of a grid medium.
constexpr int kGridLightRes = 24;
/// most cells of the homogeneous media's visibility volume.
constexpr int kFogCells = 12288;
/// most march steps through one grid box per camera ray.
constexpr int kMaxGridSteps = 24;
/// in-scatter samples per camera ray for the homogeneous media.
constexpr int kFogLightSamples = 2;
/// lights with light volumes; further lights are unshadowed in media and unattenuated by grids.
constexpr int kMaxVolumeLights = 16;

/// what a camera-ray segment through media does to the radiance L behind it: T L + L_add.
struct MediaSegment {
  Eigen::Vector3f T{1, 1, 1};
  Eigen::Vector3f L_add{0, 0, 0};
};

/// the realtime tier's per-frame media structures. Build, then the queries are thread-safe.
class RealtimeMedia {
 public:
  /// precomputes the light volumes of `media` (which must outlive this object until the next
  /// Build) for the posed `lights`; `sky_ambient` is the sphere-average sky radiance (cd/m^2).
  /// shadow rays go through `scene`; the cells are spread over `pool` (may be null).
  void Build(const MediaScene& media, const LightSampler& lights, const RayScene& scene,
             const Eigen::Vector3f& bounds_center_W, double bounds_extent_m,
             const Eigen::Vector3f& sky_ambient, ThreadPool* pool);

  /// rgb transmittance from p_W towards light j (unit direction wi, distance dist, +inf for
  /// directional lights) through every medium.
  Eigen::Vector3f LightTransmittance(int j, const Eigen::Vector3f& p_W, const Eigen::Vector3f& wi,
                                     float dist) const;

  /// single scattering along the camera ray o + t d (d unit), t in [0, t_end].
  MediaSegment IntegrateView(const LightSampler& lights, const Eigen::Vector3f& o,
                             const Eigen::Vector3f& d, float t_end, Rng* rng) const;

  const MediaScene* media() const { return media_; }
  const Eigen::Vector3f& sky_ambient() const { return sky_ambient_; }

 private:
  struct GridLight {
    int r[3] = {1, 1, 1};
    Eigen::Vector3f cells_per_m{1, 1, 1};
    float cell_m = 1;                     // smallest cell size
    std::vector<float> T;                 // [light][cell] grid transmittance to the light
    std::vector<Eigen::Vector3f> source;  // [cell] isotropic in-scatter source, cd/m^2
  };
  struct FogVolume {
    bool active = false;
    Eigen::Vector3f lo{0, 0, 0}, hi{0, 0, 0}, cells_per_m{1, 1, 1};
    int r[3] = {1, 1, 1};
    std::vector<float> vis;  // [light][cell] V Th Tgrid (channel mean)
  };
  float GridLightT(int g, int j, const Eigen::Vector3f& p_W, const Eigen::Vector3f& wi,
                   float dist) const;
  float FogVisibility(int j, const Eigen::Vector3f& p_W, const Eigen::Vector3f& wi,
                      float dist) const;

  const MediaScene* media_ = nullptr;
  Eigen::Vector3f sky_ambient_{0, 0, 0};
  int num_lights_ = 0;  // lights with volumes
  std::vector<GridLight> grid_light_;
  FogVolume fog_;
};

}  // namespace penumbra
