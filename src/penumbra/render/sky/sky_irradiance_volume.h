#pragma once
// occluded sky irradiance for the realtime tier: a precomputed irradiance volume of the static
// geometry (Greger, Shirley, Hubbard, Greenberg, "The Irradiance Volume", IEEE CG&A 1998), lit
// by the SkyModel, with probe visibility weights after Majercik, Guertin, Nowrouzezahrai,
// McGuire, "Dynamic Diffuse Global Illumination with Ray-Traced Irradiance Fields", JCGT 2019.
//
// build (once per static scene): a regular 3d grid of probes over the bounds of the finite
// static geometry (planes, finite or not, are left out of the bounds: they are floors and
// ground that would stretch the grid over the whole terrain), padded by 0.7 spacing and shifted
// by a fixed fraction of a spacing (so that probes rarely sit exactly on axis-aligned faces).
// the spacing is the smallest multiple of 1.05 of kMinSpacingM whose grid holds <= max_probes
// probes. every probe traces the same kRaysPerProbe directions against the static geoms only
// (the world body and Body::is_static; moving bodies are not baked) through a RayQuery
// (render/ray_query.h) of those geoms, built by the volume's RayQueryFactory, in batches: one
// jittered direction in each texel of a kOctSide x kOctSide octahedral map of the sphere
// (Cigolle et al., "A survey of efficient representations for independent unit vectors", JCGT
// 2014), jitter from Rng(HashKeys(kDirectionSeed, texel, 0)). per probe and texel it keeps
// whether the ray escaped (hit nothing) and its hit distance clamped to 2 spacings. a probe
// whose rays hit back faces more than kMaxBackfaceFraction of the time is inside geometry: it
// is moved just past the closest back face when that is within half a spacing and traced again
// (probe relocation, Majercik et al. 2021, "Scaling probe-based real-time dynamic global
// illumination for production", JCGT), else it is invalid. neighbours along the grid axes that
// see each other are linked.
//
// refinement of the sky's borders: a window a few metres away covers only a few texels, so
// whether their single rays escape decides most of a probe's sky light indoors, and
// neighbouring probes differed by a factor of several (dark and bright blotches on the walls).
// so a valid probe traces kSubRays more rays, one jittered in each of the kSubSide x kSubSide
// sub-cells (Rng(HashKeys(kDirectionSeed, texel, 1 + sub-cell))), in every texel whose 3 x 3
// texel neighbourhood (across the map's folded edges too) holds both an escaped and a blocked
// first-pass ray in the probe itself or in a valid probe of its 3 x 3 x 3 grid neighbourhood
// (some probes' first passes miss a window that their neighbours see); those rays say which
// sub-cells of the texel are open. hit distances stay those of the first pass (its cost:
// docs/rendering.md).
//
// lighting (whenever the sky changes): the sky radiance is projected onto real spherical
// harmonics up to l = 2 per sub-cell of each texel (one sample at the sub-cell's centre,
// weighted by the octahedral map's solid angle du dv / |x|^3), so a probe's radiance SH is the
// sum over its open sub-cells of their sky SH; the irradiance SH is that times the clamped-cosine
// convolution weights A0 = pi, A1 = 2 pi / 3, A2 = pi / 4 (Ramamoorthi and Hanrahan, "An
// efficient representation for irradiance environment maps", SIGGRAPH 2001). then a [1 2 1]
// filter along each axis over linked neighbours smooths the quantisation of small openings
// (a window 5 m away covers about 2 texels) without mixing the two sides of a wall. rays that
// hit geometry contribute no sky light (no bounce off the static surfaces).
//
// lookup at a surface point p with unit normal n (after Majercik et al. 2019, sec. 4.2): the
// point is moved off the surface, q = p + kNormalBias spacing n; of the 8 probes of the grid
// cell around q, invalid ones and those behind the tangent plane at p are skipped and each
// other one is weighted by
//   trilinear weight x ((1 + n . d) / 2)^2 (d unit from q to the probe)
//   x clamp((depth + tol - r) / tol, 0, 1),  tol = kVisibilityTolerance spacing,
// where r = |probe - q| and depth is the hit distance of the probe's ray in the texel of the
// direction towards q: a wall between the probe and q makes depth < r, so an outdoor probe's
// light does not leak through the wall (a conservative test: it rather drops probes that do see
// q than keep ones that do not). the weights are renormalised; the irradiance is the weighted
// mean of the probes' L2 irradiance at n, clamped to >= 0. when no probe passes, the darkest
// valid probe in front of the surface is used, and 0 when there is none (inside thick
// geometry); outside the grid it is the unoccluded SkyModel::Irradiance(n).
//
// thread-safety: Irradiance is const and thread-safe; Build/Relight/Update are not.
// determinism: every probe is computed on its own from fixed directions, so the volume is
// bit-identical whatever the thread count.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "penumbra/core/pose.h"
#include "penumbra/core/thread_pool.h"
#include "penumbra/render/ray_query.h"
#include "penumbra/render/sky/sky_eval_math.h"
#include "penumbra/render/sky/sky_model.h"
#include "penumbra/scene/scene_description.h"
#include "penumbra/scene/world_snapshot.h"

namespace penumbra {

/// occluded sky irradiance of the static scene on a probe grid (see the file comment).
class SkyIrradianceVolume {
 public:
  /// octahedral texels per side (256 texels; a multiple of 4).
  static constexpr int kOctSide = kSkyOctSide;
  static constexpr int kNumTexels = kOctSide * kOctSide;
  static constexpr int kRaysPerProbe = kNumTexels;  ///< first pass: one ray per texel (256)
  static constexpr int kSubSide = 4;  ///< sub-cells per texel side (refinement and lighting)
  static constexpr int kSubRays = kSubSide * kSubSide;  ///< rays in a refined texel (16)
  /// open-sky mask of a texel whose every sub-cell is open (bit s: sub-cell s open).
  static constexpr uint16_t kAllOpen = 0xffff;
  static constexpr double kMinSpacingM = 0.25;    ///< smallest probe spacing, m
  static constexpr int kDefaultMaxProbes = 4096;  ///< default cap on the probe count
  static constexpr float kMaxBackfaceFraction = 0.25f;
  /// a probe's visibility weight falls from 1 to 0 over this many spacings beyond its depth.
  static constexpr float kVisibilityTolerance = kSkyVisibilityTolerance;
  static constexpr float kNormalBias = kSkyNormalBias;  ///< lookup offset along n, in spacings
  /// a relocated probe is put this far (in spacings) past the back face it left through.
  static constexpr float kRelocateMargin = 0.05f;
  static constexpr uint64_t kDirectionSeed = 0x5ca1ab1e5c1e5ULL;

  /// an empty volume whose Build traces through queries from `make_query` (e.g. the renderer
  /// backend's; called once per Build, with a scene of the static geoms).
  /// @throws Error if make_query is empty.
  explicit SkyIrradianceVolume(RayQueryFactory make_query);

  /// traces the probes of the static geoms of `scene` posed by X_WB (one pose per body; only
  /// the static bodies' are used). with no finite static geometry the volume stays empty.
  /// the probe count is <= max_probes (clamped to [8, 65536]). clears the lighting: call
  /// Relight before Irradiance.
  /// @throws Error if X_WB.size() != scene.bodies.size(), or as the RayQueryFactory.
  void Build(const SceneDescription& scene, const std::vector<Pose>& X_WB, ThreadPool* pool,
             int max_probes = kDefaultMaxProbes);

  /// projects `sky` onto every probe's SH (a few ms for 4k probes). `sky` is only read here.
  void Relight(const SkyModel& sky, ThreadPool* pool);

  /// for the renderer, once per frame: Build when the static bodies' poses in `snapshot`
  /// differ from those of the last build (or on the first call), Relight when `sky` is not the
  /// object lit last (SkyModels are compared by address: a renderer keeps its base sky, and
  /// the effects build a new object whenever they change the sky).
  /// @throws as Build.
  void Update(const SceneDescription& scene, const WorldSnapshot& snapshot, const SkyModel& sky,
              ThreadPool* pool);

  /// true when there are no probes (no finite static geometry): Irradiance is then the
  /// unoccluded sky.
  bool empty() const { return num_probes() == 0; }

  /// sky irradiance (lux per channel) on a surface at world point p_W with unit normal n_W,
  /// occluded by the static geometry (lookup scheme in the file comment); outside the grid,
  /// or when empty, `sky`.Irradiance(n_W). requires Relight after Build.
  Eigen::Vector3f Irradiance(const Eigen::Vector3f& p_W, const Eigen::Vector3f& n_W,
                             const SkyModel& sky) const;

  /// the interpolated irradiance SH of one surface point (Blend), to be evaluated at any
  /// shading normal of that point (IrradianceAt).
  struct ShBlend {
    /// the probes' weighted mean SH in the volume's storage order (kShStride floats, padded),
    /// or zero when no probe lights the point.
    alignas(16) float c[32] = {};
    /// the point lies outside the grid (or the volume is empty): IrradianceAt gives the
    /// unoccluded SkyModel::Irradiance.
    bool open_sky = false;
  };

  /// Irradiance in two steps, for surfaces whose shading normal varies faster than their
  /// position and orientation (normal maps, smooth-shaded meshes): the probe weights of the
  /// point p_W on a surface of unit geometric normal ng_W (tangent-plane test, normal bias,
  /// visibility, the darkest-probe fallback: as Irradiance(p_W, ng_W)), and the weighted mean
  /// of the probes' SH, which IrradianceAt then evaluates at a shading normal. Blend(p, n) and
  /// IrradianceAt(that, n) give Irradiance(p, n) up to float rounding. requires Relight after
  /// Build.
  void Blend(const Eigen::Vector3f& p_W, const Eigen::Vector3f& ng_W, ShBlend* out) const;

  /// sky irradiance (lux per channel) at unit shading normal n_W of the point `blend` was made
  /// for: its SH evaluated at n_W, clamped to >= 0; `sky`.Irradiance(n_W) where the blend is
  /// open_sky.
  Eigen::Vector3f IrradianceAt(const ShBlend& blend, const Eigen::Vector3f& n_W,
                               const SkyModel& sky) const;

  /// occluded sphere-average sky radiance (cd/m^2 per channel) at a world point p_W in free
  /// space (participating media, particles): (1 / 4 pi) times the integral of the sky radiance
  /// over the directions in which p_W sees the sky past the static geometry, i.e. the l = 0
  /// band of the probes' radiance. of the 8 probes of the grid cell around p_W, invalid ones are
  /// skipped and each other one is weighted by its trilinear weight x the visibility weight of
  /// Irradiance (no normal: no tangent-plane test and no normal bias); when no probe passes, the
  /// darkest valid probe of the cell, and 0 when none is valid (inside thick geometry). outside
  /// the grid, or when empty, `open_sky` (the caller's unoccluded sphere-average radiance, e.g.
  /// SkyAmbientRadiance of effects_sky.h). in a closed room it is 0; in the open it is the sky's
  /// (up to the ground plane, which the probes do not see: planes are not in the bounds but
  /// they are traced). requires Relight after Build.
  Eigen::Vector3f AmbientRadiance(const Eigen::Vector3f& p_W,
                                  const Eigen::Vector3f& open_sky) const;

  /// sphere-average radiance of one probe (its l = 0 band; no interpolation).
  Eigen::Vector3f ProbeAmbient(int probe) const;

  /// irradiance SH of one probe evaluated at unit normal n (no interpolation, no clamping).
  Eigen::Vector3f ProbeIrradiance(int probe, const Eigen::Vector3f& n_W) const;

  int num_probes() const { return dims_[0] * dims_[1] * dims_[2]; }
  int num_valid_probes() const;
  /// probes along x, y, z.
  const std::array<int, 3>& dims() const { return dims_; }
  /// probe spacing, m.
  float spacing() const { return spacing_; }
  /// world position of probe (i, j, k) = origin + spacing (i, j, k).
  const Eigen::Vector3f& origin() const { return origin_; }
  /// index of probe (i, j, k): i + nx (j + ny k).
  int ProbeIndex(int i, int j, int k) const { return i + dims_[0] * (j + dims_[1] * k); }
  Eigen::Vector3f ProbePosition(int probe) const;
  /// where probe `probe` was traced: its grid node, or where it was relocated to.
  const Eigen::Vector3f& probe_position(int probe) const { return position_[probe]; }
  bool probe_valid(int probe) const { return valid_[probe] != 0; }
  /// which sub-cells of texel `texel` of a probe see the sky: bit s for sub-cell s = a +
  /// kSubSide b (a along u, b along v); 0 or kAllOpen for texels that were not refined.
  uint16_t open_mask(int probe, int texel) const {
    return open_[static_cast<size_t>(probe) * kNumTexels + texel];
  }
  /// texels refined in the last Build, over all valid probes (for tests and tools).
  int64_t num_refined_texels() const { return num_refined_; }

  /// the volume as plain data for the shared host/device lookup (render/sky/sky_eval_math.h:
  /// SkyVolumeBlend, SkyVolumeIrradianceAt and SkyVolumeIrradiance give Blend, IrradianceAt and
  /// Irradiance; on the CPU bit for bit). its pointers stay valid until the next Build or
  /// Relight (generation() changes).
  SkyVolumePod pod() const;
  /// counts the Builds and Relights: a copy of pod()'s arrays is current while it is unchanged.
  uint64_t generation() const { return generation_; }

  /// the octahedral texel of unit direction w, in [0, kNumTexels).
  static int TexelOf(const Eigen::Vector3f& w);

 private:
  // the probe weights of a lookup at p_W with normal n_W (Irradiance): the cell's first probe,
  // the corners in front of the surface and those with weight > 0 (bits c = dx + 2 dy + 4 dz),
  // and the weights. false outside the grid.
  struct ProbeWeights {
    int base = 0;
    unsigned front = 0, active = 0;
    alignas(16) float w[8];
  };
  bool LookupWeights(const Eigen::Vector3f& p_W, const Eigen::Vector3f& n_W,
                     ProbeWeights* out) const;
  // the corner (bit index) of the darkest probe in front of the surface, judged by its
  // irradiance luminance at n_W: the lookup's fallback when no probe sees the point; -1 when
  // none is in front.
  int DarkestFrontCorner(const ProbeWeights& pw, const Eigen::Vector3f& n_W) const;
  RayQueryFactory make_query_;
  std::array<int, 3> dims_{0, 0, 0};
  float spacing_ = 0;
  float inv_spacing_ = 0;
  Eigen::Vector3f origin_{0, 0, 0};
  std::vector<uint8_t> valid_;             // per probe
  std::vector<uint8_t> links_;             // per probe: bit 2a (+a) / 2a+1 (-a) neighbour linked
  std::vector<Eigen::Vector3f> position_;  // per probe: grid node or relocated, world
  std::vector<uint16_t> open_;             // per probe and texel: open sub-cells (open_mask)
  int64_t num_refined_ = 0;
  std::vector<float> depth_;      // per probe and texel, m (Build only)
  std::vector<uint8_t> depth_q_;  // per probe and texel, depth / depth_scale_
  float depth_scale_ = 0;         // m per depth_q_ step
  std::vector<float> sh_;         // per probe: 9 (l, m) x 3 channels, irradiance (slot order: .cc)
  // per cell (indexed by its corner probe (i, j, k) of lowest index, for i < nx - 1, j < ny - 1,
  // k < nz - 1; the rest unused): x, y, z of its 8 corner probes (corner c = dx + 2 dy + 4 dz
  // at (i + dx, j + dy, k + dz)) as 3 rows of 8 floats, NaN where the probe is invalid, so
  // that Irradiance loads them as SIMD lanes.
  std::vector<float> cell_pos_;
  // probe index of a cell's corner c minus that of its corner 0: dx + nx (dy + ny dz).
  alignas(16) std::array<int32_t, 8> corner_offset_{};
  std::vector<Pose> built_static_poses_;  // X_WB of the last Build (static bodies only)
  bool built_ = false;
  uint64_t generation_ = 0;
  const SkyModel* lit_sky_ = nullptr;
};

}  // namespace penumbra
