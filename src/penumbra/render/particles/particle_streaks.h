#pragma once
// particles (EffectsFrame::particles) as motion streaks seen by one camera exposure, without a
// ray tracer: the streaks, their per-pixel splat and their shading, shared by the CPU backend
// (whose pathtraced tier traces the same streaks as Embree curves: render/embree/particle_scene.h)
// and the CUDA backend.
//
// geometry: a particle of radius r moving at v during the exposure time T sweeps the capsule
// around the segment p + [0, T] v. this class makes the frame's streaks, and for the realtime
// tier (pixel-centre camera rays) splats them: each capsule's
// projected pixel box is scanned and the pixel-centre ray intersected with the capsule exactly
// (Quilez's ray-capsule test, render/particles/particle_math.h's IntersectCapsule), keeping the
// nearest streak per pixel (ties: lower index), which costs the streaks' screen area rather than a
// BVH traversal per pixel. a camera that moves during the exposure (camera.h) sees each row from
// its own pose: the boxes are widened by a bound of the rows' motion (StreakMotionOf,
// WidenStreakForMotion) and each row's pixels are taken in that row's pose
// (StreakRowColumnsAtPose), so every pixel whose own ray meets a capsule is tested. for the
// camera's rays of either tier (StreakRays) and a lens without distortion, drops whose widened
// capsule lies wholly outside the pyramid of the camera's rays (still, or moving over the rows) are
// skipped first (no streak, not counted as culled; they could not be drawn). streaks thinner than
// half a pixel at their distance are widened to half a pixel (radius 0.5 d / fx) and their coverage
// is scaled down by r / r_wide, so that sub-pixel drops keep their average contribution instead of
// aliasing away with one ray per pixel.
//
// coverage: a point on the streak is covered for 2r / |v| of the exposure, so a streak is
// drawn with opacity alpha = 2r / (|v| T + 2r) (1 for a still particle), times the widening
// factor; the caller alpha-composites the nearest streak over what lies behind it.
//
// shading (approximations, documented in the report):
//  - rain: a drop refracts a wide-angle view of its surroundings (Garg and Nayar, "Vision and
//    rain", IJCV 2007: a drop's radiance is close to the mean environment radiance over a
//    ~165 degree field of view); drawn as colour x (sphere-average sky radiance + sum_j E_j /
//    (4 pi)), i.e. the mean environment radiance times the transmission tint `color`.
//  - snow: Lambertian of albedo `color` on the capsule's normal, lit by every light
//    (unshadowed) and the sphere-average sky radiance.
//  the sphere-average sky radiance is the one the static geometry lets through at the particle
//  (SkyIrradianceVolume::AmbientRadiance) when the renderer hands a sky volume over (both
//  tiers), else the open sky's.
//  - sparks: emit ParticleSet::emission.
// culling (realtime tier only, rain only): a rain streak is not drawn when its coverage times
// an upper bound of the homogeneous media's transmittance from the camera to the streak's
// nearest point (smallest sigma_t channel, smallest density of the segment's ends, media that
// hold the whole segment; grid media ignored) is below kRainCullContrast. the streak's radiance
// (the mean environment radiance, see shading) and what lies behind it are both within the
// displayed range for most pixels, so their difference after exposure is at most display white and
// the streak changes the display-linear pixel value by less than one 8-bit step (1/255). this is an
// approximation: against a background or drop brighter than white the bound does not hold
// (both clip, so the change is small there too), and the sRGB curve magnifies display-linear
// steps near black (slope up to 12.92), so a culled streak over a very dark pixel could have
// changed it by a few codes; a culled streak also no longer hides the streaks behind it.
// culling concerns sub-pixel drops far from the lens (coverage falls with distance as
// r^2 fx / (d |v| T) once widened to half a pixel) and drops deep in fog; drops near the lens
// have coverage near 1 and are always drawn. sparks (emissive) and snow are never culled.
// every drop's decision (nothing, culled or a streak) is render/particles/streak_cull_math.h's
// StreakCullDrop, which the CUDA backend's device culling (render/cuda/cuda_streak_cull.h)
// calls too.
// particles cast no shadows and are not seen by secondary rays (reflections, shadow rays);
// they do not change the depth or segmentation images.

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <vector>

#include "penumbra/core/thread_pool.h"
#include "penumbra/render/camera/camera.h"
#include "penumbra/render/light/light_sampler.h"
#include "penumbra/render/media/media_scene.h"
#include "penumbra/render/particles/particle_math.h"
#include "penumbra/render/particles/shelter_map.h"
#include "penumbra/render/particles/streak_cull_math.h"
#include "penumbra/render/sky/sky_irradiance_volume.h"
#include "penumbra/scene/effects_frame.h"

namespace penumbra {

/// which rays a ParticleStreaks::Build serves, and so which drops it may leave out.
enum class StreakRays : uint8_t {
  /// rays from anywhere: every drop with a positive radius (unsheltered) is a streak.
  kAny,
  /// the camera's rays through any point of its image (the pathtraced tier's camera rays, whose
  /// pixel samples are jittered over the whole pixel): with a lens without distortion, the drops
  /// whose widened capsule lies wholly outside the camera's view pyramid (every pixel's area,
  /// widened by half a pixel at the drop's distance; for a moving camera, by the pyramid's
  /// motion over the rows) are left out, since no such ray can meet them.
  kCamera,
  /// the pixel-centre rays of the realtime tier: as kCamera, and the drops wholly behind the
  /// near plane and the invisible rain streaks (kRainCullContrast) are left out, and each
  /// pixel's nearest streak is found (PixelHit).
  kPixelCentres,
};

/// the motion of `camera`'s rows during its exposure as the streaks' culling and the realtime
/// splat bound it (particle_math.h's StreakMotion: the largest turn and shift of any row's pose,
/// rows v in [-0.5, height], from X_WO, 1 % and 1e-6 to spare, and the largest tan of a pixel
/// centre's polar angle); zero for a still camera.
StreakMotion StreakMotionOf(const Camera& camera);

/// every row's pose of a moving `camera` (Camera::PoseAtRow(v), v = 0 .. height - 1) as 12
/// doubles per row into *rows (resized to 12 x height): R_WO row-major, then the origin (world,
/// m); the layout of StreakSplatView::rows and StreakRowColumnsAtPose.
void StreakRowPoses(const Camera& camera, std::vector<double>* rows);

/// a frame's inputs of the shared per-drop decision (render/particles/streak_cull_math.h's
/// StreakCullDrop, which ParticleStreaks::Build and the CUDA backend's device culling call): the
/// camera and culling pod, the homogeneous media it points at and every particle set's flags.
struct StreakCullSetup {
  /// frame.media points into `media` and frame.shelter into the ShelterMap's roof: valid while
  /// both live unchanged (copying this struct does not move them).
  StreakCullFrame frame;
  std::vector<StreakCullMedium> media;
  std::vector<StreakCullSet> sets;  ///< per EffectsFrame::particles entry
};

/// fills *out for the drops of `fx` seen by `camera` over an exposure of exposure_time_sec
/// (>= 0) serving `rays` (StreakRays: which tests apply), the homogeneous media of `media` (may
/// be null: coverage alone) and `shelter` (may be null), as ParticleStreaks::Build decides them.
void StreakCullSetupOf(const EffectsFrame& fx, const Camera& camera, double exposure_time_sec,
                       StreakRays rays, const MediaScene* media, const ShelterMap* shelter,
                       StreakCullSetup* out);

/// the nearest streak along a ray.
struct ParticleHit {
  float t = 0;                    ///< ray parameter (units of |ray.d|)
  Eigen::Vector3f ng_W{0, 0, 1};  ///< unit normal of the capsule, facing the ray
  float alpha = 0;                ///< coverage in (0, 1]
  ParticleKind kind = ParticleKind::kRain;
  int set = 0;    ///< index into EffectsFrame::particles
  int prim = -1;  ///< streak index in the ParticleScene
};

/// the streaks of one frame and camera. Build, then PixelHit and Shade are thread-safe.
class ParticleStreaks {
 public:
  ParticleStreaks() = default;
  ParticleStreaks(const ParticleStreaks&) = delete;
  ParticleStreaks& operator=(const ParticleStreaks&) = delete;

  /// builds the streaks of `fx` (null = none) for `camera` and an exposure of
  /// exposure_time_sec (>= 0). the frame must outlive this object until the next Build.
  /// @throws ConfigError if a set's arrays differ in length or hold non-finite values
  /// (key effects.particles[i]).
  /// `rays`: the rays the streaks serve (StreakRays), which decides the drops left out; with
  /// kPixelCentres the per-pixel nearest streaks of the camera's pixel-centre rays are built
  /// too (PixelHit), in bands of rows over `pool` (may be null), and invisible rain streaks are
  /// culled (kRainCullContrast) using the homogeneous media of `media` (may be null: coverage
  /// alone). `shelter` (may be null): rain drops and snowflakes that it shelters (static geometry
  /// above them) are not drawn unless their set says otherwise (ParticleSet::sheltered);
  /// sparks always are.
  void Build(const EffectsFrame* fx, const Camera& camera, double exposure_time_sec,
             StreakRays rays, ThreadPool* pool = nullptr, const MediaScene* media = nullptr,
             const ShelterMap* shelter = nullptr);

  /// whether Build with StreakRays::kPixelCentres also splats the streaks on the host (default
  /// true); false: Build culls as for the realtime tier (near plane, frustum,
  /// kRainCullContrast) but leaves the per-pixel splat to the caller (PixelHit finds nothing; the
  /// CUDA backend's splat kernel makes it from ends(), alpha() and set_of() with the shared
  /// functions of render/particles/particle_math.h: ProjectStreak, StreakRowColumns,
  /// IntersectCapsuleRay).
  void set_host_splat(bool on) { host_splat_ = on; }
  bool host_splat() const { return host_splat_; }

  /// whether Build decides the drops on the host (default true); false: Build checks the sets'
  /// lengths and prepares the decision's inputs (cull_setup) but makes no streak (empty, and no
  /// non-finite check): the CUDA backend's device culling decides the drops from cull_setup
  /// (render/cuda/cuda_streak_cull.h).
  void set_host_culling(bool on) { host_culling_ = on; }
  bool host_culling() const { return host_culling_; }

  bool empty() const { return count_ == 0; }
  int size() const { return count_; }
  /// rain streaks culled as invisible by the last Build.
  int culled() const { return culled_; }

  /// whether some streak meets pixel (u, v)'s pixel-centre ray (Build with kPixelCentres;
  /// false without): PixelHit with tmax = infinity would find it, without the ray.
  bool PixelHasStreak(int u, int v) const {
    return pixel_hits_built_ && pixel_[static_cast<size_t>(v) * pixel_w_ + u].prim >= 0;
  }
  /// the nearest streak of the pixel-centre camera ray `ray` of pixel (u, v) within (0, tmax]
  /// (Build with kPixelCentres); false if none.
  bool PixelHit(const Ray& ray, int u, int v, float tmax, ParticleHit* hit) const;

  /// evaluates every rain streak's radiance once, at its centre (rain shading does not depend
  /// on the hit point's normal), so that Shade looks it up; spread over `pool` (may be null).
  /// `sky_volume` (may be null; must outlive this object until the next call) occludes the
  /// sky light of every particle from here on (Shade): the sky term is then
  /// SkyIrradianceVolume::AmbientRadiance at the particle instead of `sky_ambient`.
  void PrecomputeRain(const LightSampler& lights, const Eigen::Vector3f& sky_ambient,
                      const SkyIrradianceVolume* sky_volume, ThreadPool* pool);

  /// radiance (cd/m^2) of the streak at `hit`, point p_W; `sky_ambient` is the open sky's
  /// sphere-average radiance (occluded at p_W by the sky volume of the last PrecomputeRain, if
  /// any). the shared ShadeStreak of render/particles/particle_math.h (the CUDA backend's paths
  /// call it too).
  Eigen::Vector3f Shade(const ParticleHit& hit, const Eigen::Vector3f& p_W,
                        const LightSampler& lights, const Eigen::Vector3f& sky_ambient) const;

  /// particle set `set` of the frame (an index into EffectsFrame::particles) as ShadeStreak
  /// takes it.
  StreakSetPod SetPod(int set) const;
  /// the inputs of the last Build's per-drop decision (StreakCullSetupOf; unset when that
  /// frame had no particles): the CUDA backend's device culling decides the same drops.
  const StreakCullSetup& cull_setup() const { return cull_; }
  /// the frame of the last Build (null: none).
  const EffectsFrame* frame() const { return fx_; }
  /// per streak (size() of them): its coverage alpha in (0, 1] and its particle set.
  const std::vector<float>& alpha() const { return alpha_; }
  const std::vector<int>& set_of() const { return set_; }
  /// per streak both ends of its axis (x, y, z in world m; w the widened radius in m, equal at
  /// both ends): streak n is ends()[2 n] to ends()[2 n + 1].
  const std::vector<Eigen::Vector4f>& ends() const { return ends_; }
  /// per streak the rain radiance of the last PrecomputeRain (cd/m^2; size() entries, 0 for
  /// other kinds), or empty (no rain, or not precomputed).
  const std::vector<Eigen::Vector3f>& rain_radiance() const { return rain_radiance_; }
  /// the sky volume of the last PrecomputeRain (null: the open sky's radiance).
  const SkyIrradianceVolume* sky_volume() const { return sky_volume_; }

 protected:
  const EffectsFrame* fx_ = nullptr;
  int count_ = 0;
  int culled_ = 0;
  std::vector<float> alpha_;           // per primitive
  std::vector<int> set_;               // per primitive
  std::vector<Eigen::Vector4f> ends_;  // per primitive: both ends (x, y, z, widened radius)
  int pixel_w_ = 0;
  struct PixelStreak {
    float t = std::numeric_limits<float>::infinity();  // nearest streak t (ray units), +inf none
    int prim = -1;                                     // its primitive, -1 none
  };
  std::vector<PixelStreak> pixel_;                   // per pixel (one load per PixelHit)
  std::vector<Eigen::Vector3f> rain_radiance_;       // per primitive (PrecomputeRain), or empty
  const SkyIrradianceVolume* sky_volume_ = nullptr;  // occluded sky (PrecomputeRain), or null
  std::vector<uint8_t> visible_;   // per primitive: in the image (BuildPixelHits), or empty
  bool pixel_hits_built_ = false;  // pixel_ holds this frame's hits
  bool host_splat_ = true;         // Build with kPixelCentres splats (BuildPixelHits)
  bool host_culling_ = true;       // Build decides the drops
  std::vector<double> row_poses_;  // a moving camera's row poses (BuildPixelHits)
  // the streaks one chunk of drops keeps, in order (Build; kept between frames for their
  // capacity).
  struct DropChunk {
    std::vector<float> alpha;
    std::vector<int> set;
    std::vector<Eigen::Vector4f> ends;  // both ends per streak
    int culled = 0;
    size_t bad = 0;  // index of the chunk's first non-finite particle, or the particle count
  };
  std::vector<DropChunk> drop_chunks_;
  StreakCullSetup cull_;  // the last Build's decision inputs

 private:
  void BuildPixelHits(const Camera& camera, ThreadPool* pool);
};

}  // namespace penumbra
