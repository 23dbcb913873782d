#pragma once
// the host side of the CUDA backend's realtime tier (render/transport/realtime.h): the scene's
// materials, 2d textures (every mip level) and geoms as plain data, made once; per frame the
// posed lights (LightSampler), the geoms' poses, the pinhole camera and the frame's random-number
// key; the frame's effects (light scales and extra lights through
// LightSampler::Update, the moved or scaled sky and the surface wetness through
// render/sky/effects_sky.h, as the CPU backend's MediaFrame), particles (rain, snow, sparks: the
// drops culled on the host with the CPU's render/particles/particle_streaks.h, the streaks then
// splatted, shaded and drawn over each pixel by the frame itself, StreakSplatView) and media
// (homogeneous and grids:
// PrepareMedia, RealtimeMedia's layouts built on the host and its four volumes (the grids' light
// volumes and froxels, the world light volume, the fog froxels) by the frame itself on the
// device; the kernels' view pass draws them and
// the streaks seen through them); the sky model and sky volume (render/cuda's SkyDataOf, for
// DeviceRealtime::UploadSky) and, for the host path, the per-pixel sky terms from the primary rays'
// geometry (QuadSkyTerms of render/transport/realtime_shading.h: the shared lookups of
// render/sky/sky_eval_math.h, which the device's sky kernel runs too) and those of the mirror
// layer's reflected rays (MirrorSkyTerms); and the film's exposure and encoding table.
// render/cuda/realtime_host.h's RenderRealtimeOnHost runs the GPU path's per-pixel functions on
// the CPU over the host BVH (tests). plain C++: both backends read it (render/frame).

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "penumbra/core/image.h"
#include "penumbra/core/thread_pool.h"
#include "penumbra/render/film/film.h"
#include "penumbra/render/frame/bvh_scene.h"
#include "penumbra/render/frame/camera_rays.h"
#include "penumbra/render/frame/path_streak_build.h"
#include "penumbra/render/light/light_sampler.h"
#include "penumbra/render/media/media_realtime.h"
#include "penumbra/render/media/media_scene.h"
#include "penumbra/render/particles/particle_streaks.h"
#include "penumbra/render/particles/shelter_map.h"
#include "penumbra/render/ray_query.h"
#include "penumbra/render/render_settings.h"
#include "penumbra/render/renderer.h"
#include "penumbra/render/sky/effects_sky.h"
#include "penumbra/render/sky/sky_irradiance_volume.h"
#include "penumbra/render/sky/sky_model.h"
#include "penumbra/render/transport/realtime.h"

namespace penumbra::cuda {

/// the plain data of a scene's realtime frames (file comment). not thread-safe.
class RealtimeFrameData {
 public:
  /// copies the materials, textures and geoms of `scene` (referenced: it must outlive this).
  /// `settings`: the tier's film, anisotropy and seed. `statics_query` makes the ray queries
  /// over the static geoms that the sky irradiance volume and the shelter map trace when they
  /// are built (empty: BvhRayQuery, our traversal on the CPU; CudaRenderer and the batch pass
  /// theirs: MakeRenderer's renderer Embree's, as the CPU backend's maps).
  /// @throws Error if a texture has more than kMaxTextureLevels levels.
  RealtimeFrameData(const SceneDescription& scene, const RenderSettings& settings,
                    RayQueryFactory statics_query = RayQueryFactory());

  /// poses the lights and geoms from `snapshot`, applies the lighting `effects` (null: none),
  /// sets the camera and frame key of `view`, and
  /// updates the sky volume (built on the first call and when the static bodies move, relit
  /// when the effects change the sky): PoseWorld, then SetCamera, then PrepareStreaks, then
  /// PrepareMedia. a camera with lens distortion or motion gets its ray tables (camera_rays.h),
  /// the camera() pointing to their host arrays: `rays` if given (the caller Prepared them for
  /// `view` and keeps them alive), else tables this object fills. `media_rays`: PrepareMedia's
  /// shadow rays (see there). `streaks` false: PrepareStreaks is left out and the frame has no
  /// streaks (those of an earlier frame are dropped) until the caller calls it, after PrepareMedia
  /// (the same streaks: PrepareStreaks reads nothing PrepareMedia writes); CudaRenderer does so
  /// while the GPU shades (CudaRenderer's late streaks).
  /// @throws ConfigError for effects out of range (a negative light or sky scale, a wetness
  /// outside [0, 1]), as the CPU backend; with `streaks`, as PrepareStreaks.
  void Prepare(const WorldSnapshot& snapshot, const CameraView& view, ThreadPool* pool,
               const EffectsFrame* effects = nullptr, const CameraRayTables* rays = nullptr,
               const RayQuery* media_rays = nullptr, bool streaks = true);
  /// the media of the frame (View's media, has_media): with homogeneous or grid media in
  /// `effects` (null or none: no media), the CPU backend's RealtimeMedia (render/
  /// media_realtime.h) built as its MediaFrame builds it, for `camera` and the frame key of
  /// `view`, with the frame's lights, sky and occluded sky volume; RealtimeMedia::HostView's
  /// arrays for the view. the grids' light volumes and froxels, the world light volume's cells
  /// and the fog froxels are left to the frame (View's media_build: the device's
  /// MediaGridLightKernel, MediaGridFroxelKernel, MediaLightVolumeKernel and MediaFogSliceKernel,
  /// or BuildMediaVolumesOnHost), with the grids' arrays. `media_rays`: the shadow rays of the
  /// layouts' host part (any RayQuery posed for `snapshot`: CudaRenderer passes one over its
  /// device scene), or, if null, a BvhRayQuery (the kernels' traversal on the host) this object
  /// keeps and poses. call after PoseWorld (Prepare does).
  void PrepareMedia(const WorldSnapshot& snapshot, const EffectsFrame* effects,
                    const Camera& camera, const CameraView& view, ThreadPool* pool,
                    const RayQuery* media_rays = nullptr);
  /// whether the last Prepare built media (View's has_media), and host milliseconds its
  /// RealtimeMedia::Build took (benchmarks), and its stages'.
  bool has_media() const { return media_ready_; }
  double media_build_ms() const { return media_build_ms_; }
  /// host milliseconds the last Prepare spent in the sky irradiance volume's Update (its build
  /// or relight, on the host; about 0 when neither was due) and in the shelter map's Update
  /// (its build; 0 without sheltered particles): a new renderer's first frame pays the builds
  /// (benchmarks).
  double volume_update_ms() const { return volume_update_ms_; }
  double shelter_update_ms() const { return shelter_update_ms_; }
  const RealtimeMedia::BuildTimes& media_build_times() const {
    return realtime_media_.build_times();
  }
  /// the camera-independent part of Prepare: the lights, the geoms (their transforms made
  /// again only for bodies whose pose changed since the last call), the effects' sky and
  /// wetness and the sky volume. @throws as Prepare.
  void PoseWorld(const WorldSnapshot& snapshot, ThreadPool* pool,
                 const EffectsFrame* effects = nullptr);
  /// the camera part of Prepare: the pinhole camera, its pixel spread (radians), the frame's
  /// random-number key (FrameContext::FrameKey of the settings' seed, camera_index and
  /// frame_index) and the view's white-balance gains (Ev100's exposures).
  void SetCamera(const PinholeCamera& camera, float spread_rad, int camera_index,
                 int64_t frame_index,
                 const Eigen::Vector3f& white_balance_gains = Eigen::Vector3f::Ones());
  /// the particle streaks of the frame (View's splat, or streaks): with particles in `effects`
  /// (null or none: no streaks), the CPU backend's ParticleStreaks of `camera` (render/
  /// particle_streaks.h: the drops a ShelterMap shelters left out, rain the frame's homogeneous
  /// media hide culled; with a device drop culler, set_device_drop_culler, the culler decides the
  /// drops); the streaks in index order and the camera's projection for the frame's own splat
  /// (splat_streaks(), View's splat: the device's splat kernels, or RenderRealtimeOnHost, find
  /// and shade each pixel's nearest streak); the media in front of a streak are applied in the
  /// view pass (MediaViewQuad). call after PoseWorld (Prepare does). under the pathtraced tier's
  /// settings instead, as the CPU's MediaFrame::Prepare for that tier: the streaks without the
  /// per-pixel splat and culling, every rain streak shaded once, and their BVH for the paths
  /// (path_streaks(); no streak pixels).
  /// @throws ConfigError for malformed particle sets (ParticleStreaks::Build).
  void PrepareStreaks(const WorldSnapshot& snapshot, const EffectsFrame* effects,
                      const Camera& camera, const CameraView& view, ThreadPool* pool);
  /// the streaks the frame splats itself (empty without particles or under the
  /// pathtraced tier's settings): PathStreakBuild::View as View's splat.streaks. with a device
  /// drop culler (set_device_drop_culler) the streaks stay on the device for the frame's splat;
  /// this call copies them to the host (DeviceStreakList::download: it waits for the culling)
  /// the first time after a PrepareStreaks (tests and benchmarks).
  const PathStreakBuild& splat_streaks() const;
  /// whether a device drop culler is set (set_device_drop_culler).
  bool has_drop_culler() const { return static_cast<bool>(device_drop_culler_); }
  /// streaks a device drop culler made and keeps on the device: the frame's
  /// splat reads them in place (StreakSplatView: streaks.streaks, bound as streaks.num, count)
  /// without the host waiting for the culling or copying them.
  struct DeviceStreakList {
    /// device memory: the drawn streaks in index order (StreakPod, prim = the index), as
    /// ParticleStreaks::Build makes them; at most `bound` of them.
    const StreakPod* streaks = nullptr;
    /// a bound of their count the host knows without waiting (the drops'; 0: no streaks).
    int32_t bound = 0;
    /// device memory: their count, written by the culler's queued work, which the frame's
    /// device work waits for (the culler's business).
    const int32_t* count = nullptr;
    /// copies the streaks to *out (resized to their count); waits for the culling. may throw
    /// the culler's errors (ConfigError for a non-finite drop).
    std::function<void(std::vector<StreakPod>* out)> download;
  };
  /// the drops' culling on the device, without the host's wait
  /// (CudaRenderer sets it): under the realtime tier's settings, PrepareStreaks has ParticleStreaks
  /// prepare the decision's inputs only (set_host_culling(false): the sets' lengths checked, no
  /// drop decided) and calls it with the frame's effects and those inputs; it queues its work (the
  /// drawn streaks in index order, StreakPod, prim = the index, as ParticleStreaks::Build makes
  /// them) and returns where its streaks will be (DeviceStreakList); the culled rain and any
  /// non-finite drop are known once the frame's device work is done: the caller then reports the
  /// culled rain (FinishDeviceCulling) or throws the culler's ConfigError. empty (the default): the
  /// host decides the drops.
  using DeviceDropCuller =
      std::function<DeviceStreakList(const EffectsFrame& fx, const StreakCullSetup& setup)>;
  void set_device_drop_culler(DeviceDropCuller culler) { device_drop_culler_ = std::move(culler); }
  /// after a frame whose streaks a device drop culler made: the rain it culled as invisible
  /// (ParticleStreaks::culled), for streaks_culled.
  void FinishDeviceCulling(int culled) { streaks_culled_ = culled; }
  /// rain streaks culled as invisible by the last PrepareStreaks (host or device culling; a
  /// device drop culler's once FinishDeviceCulling reported it, 0 before).
  int streaks_culled() const { return streaks_culled_; }
  /// the frame's streaks of the last PrepareStreaks (ParticleStreaks: with the device culling
  /// only its decision's inputs, cull_setup).
  const ParticleStreaks& particles() const { return particles_; }
  /// the pathtraced tier's streaks of the last PrepareStreaks (empty under the realtime tier's
  /// settings or without particles); PathStreakBuild::View gives the paths' PathStreaks.
  const PathStreakBuild& path_streaks() const { return path_streaks_; }
  /// the random-number key of a frame of camera `camera_index`, frame `frame_index`
  /// (FrameContext::FrameKey, render/cpu/integrator.h) under these settings' seed.
  uint64_t FrameKey(int camera_index, int64_t frame_index) const;

  /// the sky term of every pixel (RealtimeFrameView::sky_term) from its primary geometry, n =
  /// the Prepared camera's width x height pixels, row-major; with a sky volume a 2x2 quad on one
  /// flat face shares one probe blend, as RealtimeIntegrator does. only rows [row0, row1) are
  /// read and written (row1 < 0: to the last row); the bits of a pixel do not depend on the
  /// rows asked for. @throws Error for another n, an odd row0, or an odd row1 before the last
  /// row + 1.
  void SkyTerms(const PixelGeometry* geometry, int64_t n, Float3* out, ThreadPool* pool,
                int row0 = 0, int row1 = -1) const;

  /// the sky term of every pixel's mirrored ray (RealtimeFrameView::mirror_sky) from its
  /// geometry (TraceMirrorRay; n pixels as SkyTerms): where it hits, the occluded sky
  /// irradiance at the hit's shading normal (SkyIrradianceVolume::Irradiance, no shared blends:
  /// render/cpu/mirror_layer.cc's MirrorRadiance), where it escapes SkyModel::Background;
  /// pixels that traced none (hit -1) are left as they are; rows [row0, row1) only, as
  /// SkyTerms. @throws as SkyTerms.
  void MirrorSkyTerms(const PixelGeometry* mirror, int64_t n, Float3* out, ThreadPool* pool,
                      int row0 = 0, int row1 = -1) const;

  /// SkyTerms and, where `mirror` is not null, MirrorSkyTerms of rows [row0, row1) in one
  /// parallel loop over pairs of rows (the same bits as the two calls). @throws as SkyTerms.
  void FrameSkyTerms(const PixelGeometry* geometry, const PixelGeometry* mirror, int64_t n,
                     Float3* sky, Float3* mirror_sky, ThreadPool* pool, int row0, int row1) const;

  /// the frame's occluded sky irradiance volume (the sky's plain data for the device copies:
  /// render/cuda's SkyDataOf); current while sky_generation() is unchanged.
  const SkyIrradianceVolume& sky_volume() const { return volume_; }
  /// changes whenever Prepare rebuilt or relit the sky volume (also when the effects changed
  /// the sky: the volume is relit with it).
  uint64_t sky_generation() const { return volume_.generation(); }

  /// whether some material has a mirror layer (MaterialPod::mirror > 0): frames without one
  /// skip the layer's kernels and its part of the host's sky pass.
  bool any_mirror() const { return any_mirror_; }

  /// the frame's view with host pointers (scene: the traversal's arrays; sky: per pixel).
  RealtimeFrameView View(const SceneView& scene, const Float3* sky) const;
  /// sets the particle streak fields of *f (splat: the frame's splat's streaks, host arrays, or
  /// with a device drop culler its device array, a bound and the device count, and the camera's
  /// projection) to those of the last PrepareStreaks (none after a Prepare without streaks), as
  /// View sets them: the late streaks that CudaRenderer hands to DeviceRealtime::Render's
  /// `streaks`. the arrays stay valid until the next Prepare or PrepareStreaks.
  void StreakFields(RealtimeFrameView* f) const;

  /// the EV100 of a frame whose rows' log-luminance sums are `row_sums` (film.h's auto
  /// exposure on their mean, or the manual EV100), and the per-channel exposures of Develop
  /// (the exposure times the prepared view's white_balance_gains, as Film::Develop).
  double Ev100(const std::vector<double>& row_sums, int64_t pixels, float exposure[3]) const;

  const std::vector<MaterialPod>& materials() const { return materials_; }
  const std::vector<TexturePod>& textures() const { return textures_; }
  const std::vector<uint8_t>& texels() const { return texels_; }
  const std::vector<GeomPod>& geoms() const { return geoms_; }
  const std::vector<LightPod>& lights() const { return lights_.pods(); }
  const PinholeCamera& camera() const { return camera_; }
  const Film& film() const { return film_; }
  const RenderSettings& settings() const { return settings_; }
  /// the sky of the prepared frame (the scene's, or the effects' moved and scaled one).
  const SkyModel& frame_sky() const { return *frame_sky_; }

 private:
  const SceneDescription& scene_;
  RenderSettings settings_;
  std::vector<MaterialPod> materials_;
  MaterialPod default_material_;
  std::vector<TexturePod> textures_;
  std::vector<uint8_t> texels_;
  std::vector<GeomPod> geoms_;
  LightSampler lights_;
  SkyModel sky_;                       // the scene's sky
  EffectsSky effects_sky_;             // the effects' sky (moved sun, scaled luminance)
  const SkyModel* frame_sky_ = &sky_;  // the frame's: sky_ or effects_sky_'s
  float wetness_ = 0;                  // EffectsFrame::surface_wetness of the frame
  SkyIrradianceVolume volume_;
  ShelterMap shelter_;            // where rain and snow do not fall (PrepareStreaks)
  ParticleStreaks particles_;     // the frame's streaks (PrepareStreaks)
  PathStreakBuild path_streaks_;  // the pathtraced tier's streaks and BVH (PrepareStreaks)
  // the realtime streaks in index order; with a device drop culler only the
  // sets, and the streaks once splat_streaks downloads them (device_pods_copied_)
  mutable PathStreakBuild splat_streaks_;
  StreakSplatView splat_camera_;             // their projection (R_OW, p_OW, intrinsics; rows)
  std::vector<double> splat_rows_;           // a moving camera's row poses (StreakSplatView::rows)
  DeviceDropCuller device_drop_culler_;      // the device's culling (empty: the host's)
  DeviceStreakList device_list_;             // their place (bound 0: none, or the host's list)
  mutable bool device_pods_copied_ = false;  // splat_streaks_ holds them (splat_streaks)
  int streaks_culled_ = 0;                   // rain culled by the last PrepareStreaks
  // the camera's projection for the frame's splat (splat_camera_, splat_rows_)
  void SetSplatCamera(const Camera& camera);
  // the frame's media (PrepareMedia): the scene's media, their realtime volumes and their host
  // view (the froxels' records as Rgb4, the grids' light volumes, the sky volume's pod);
  // media_ready_ false until PrepareMedia built them for the frame (PoseWorld clears it)
  MediaScene media_;
  RealtimeMedia realtime_media_;
  std::unique_ptr<RayQuery> media_query_;  // PrepareMedia's own shadow rays (BvhRayQuery)
  RealtimeMediaHostArrays media_arrays_;
  bool media_scene_built_ = false;  // media_ holds the frame's effects (BuildMediaScene)
  // media_ built from the frame's effects `fx`, once per PoseWorld (PrepareStreaks' rain culling
  // and PrepareMedia read it)
  void BuildMediaScene(const EffectsFrame* fx);
  RealtimeMediaView media_view_;
  bool media_ready_ = false;
  double media_build_ms_ = 0;
  double volume_update_ms_ = 0;
  double shelter_update_ms_ = 0;
  Film film_;
  PinholeCamera camera_;
  CameraRayTables camera_rays_;  // Prepare's view's tables when the caller gives none
  Eigen::Vector3f white_balance_gains_ = Eigen::Vector3f::Ones();  // the prepared view's
  // drops the streaks of an earlier frame (PrepareStreaks, and Prepare without streaks).
  void ClearStreaks();
  // the checks of SkyTerms (n, row bounds); returns row1 resolved (< 0: the last row + 1).
  int CheckRows(const char* what, int64_t n, int row0, int row1) const;
  // the sky terms of the pixels of rows 2 q and 2 q + 1 below row1 (SkyTerms' 2x2 quads).
  void SkyQuadRow(const PixelGeometry* geometry, Float3* out, int q, int row1) const;
  // the mirrored rays' sky terms of row v (MirrorSkyTerms).
  void MirrorSkyRow(const PixelGeometry* mirror, Float3* out, int v) const;
  float spread_rad_ = 0;
  uint64_t frame_key_ = 0;
  bool any_mirror_ = false;
  // the body poses of the last PoseWorld (geoms_' transforms are theirs) and, per body, whether
  // it moved since (PoseWorld poses only those bodies' geoms)
  std::vector<Pose> posed_X_WB_;
  std::vector<uint8_t> body_moved_;
};

/// the pinhole camera of `view` as the kernels take it (view must be a projective camera).
PinholeCamera PinholeCameraOf(const CameraView& view);

}  // namespace penumbra::cuda
