#pragma once
// the CUDA backend's Renderer (render/renderer.h). on the GPU now, for a pinhole camera (with
// lens distortion or motion too: camera_rays.h) under clear conditions, lighting effects (light
// scales, extra lights, a moved or scaled sky, surface wetness), particles, homogeneous and grid
// media and particles seen through them: the images
// of the pixel centre's primary ray (depth, segmentation (geom ids), instance (body) and semantic
// segmentation, range and normals, traced by bvh_traversal.h's code in cuda_kernels.cu) and, in the
// realtime tier, rgb and radiance (render/transport's realtime chain in realtime_kernels.cuh's
// kernels; the frame's preparation on the host, realtime_frame.h), and in the pathtraced tier rgb
// and radiance with media and particles too (render/transport's path chain): every frame of both
// tiers renders on the GPU (the host prepares each frame and, in the pathtraced tier, denoises
// and develops it); docs/gpu.md lists what is where.
//
// a realtime frame with particles makes its streaks late: Render prepares the frame without
// them (RealtimeFrameData::Prepare's `streaks` false), queues the device's work up to the
// shading, and makes the streaks (RealtimeFrameData::PrepareStreaks) while the GPU traces and
// shades (DeviceRealtime::Render's `streaks`); their drops are culled on the device
// (DeviceStreakCull, cuda_streak_cull.h, through RealtimeFrameData's device drop culler: the
// CPU's StreakCullDrop one thread each, compacted in order), where the streaks stay for the
// splat, and the culled rain and a non-finite drop's ConfigError come once the frame's outputs
// are back, before Render returns. the same bits as streaks made and culled on the host before
// any device work.

#include <chrono>
#include <memory>
#include <vector>

#include "penumbra/core/thread_pool.h"
#include "penumbra/render/cuda/cuda_kernels.h"
#include "penumbra/render/cuda/cuda_path.h"
#include "penumbra/render/cuda/cuda_ray_query.h"
#include "penumbra/render/cuda/cuda_realtime.h"
#include "penumbra/render/cuda/cuda_streak_cull.h"
#include "penumbra/render/frame/bvh_scene.h"
#include "penumbra/render/frame/camera_rays.h"
#include "penumbra/render/frame/path_frame.h"
#include "penumbra/render/frame/realtime_frame.h"
#include "penumbra/render/renderer.h"
#include "penumbra/scene/effects_frame.h"

namespace penumbra::cuda {

/// the drops of fx's particle sets (ParticleSet's position_W, velocity_W, radius_m) as
/// DeviceStreakCull takes them: one DropSet a set, pointing into fx (valid while fx is).
std::vector<DropSet> DropSetsOf(const EffectsFrame& fx);

/// Renderer on the GPU (see the file comment).
class CudaRenderer final : public Renderer {
 public:
  /// copies `scene` and builds its BVH on the host and device.
  /// @throws Error as BvhScene, or if the CUDA runtime fails.
  explicit CudaRenderer(const SceneDescription& scene);
  /// as above, with the render settings of the GPU's rgb (tier, film, anisotropy, seed; the
  /// one-argument form takes the default RenderSettings). `statics_query` makes the ray queries
  /// the realtime tier's static maps (sky irradiance volume, shelter map) are traced through
  /// before the first frame and when a static body moves (RealtimeFrameData); empty: BvhRayQuery
  /// over the renderer's host threads. MakeRenderer passes Embree's (StaticMapsQueryFactory,
  /// render/backends/renderer_factory.h), the CPU backend's.
  CudaRenderer(const SceneDescription& scene, const RenderSettings& settings,
               RayQueryFactory statics_query = RayQueryFactory());
  ~CudaRenderer() override;

  void Render(const WorldSnapshot& snapshot, const EffectsFrame* effects, const CameraView& view,
              RenderedFrame* out) override;

  /// frames rendered so far (every one on the GPU).
  int64_t gpu_frames() const { return gpu_frames_; }

  /// the host threads of the renderer's pool (RenderSettings::threads, 0 = every core),
  /// calling thread included: its BVH builds, copies and host shading run over them.
  int host_threads() const { return pool_->num_threads(); }

  /// the scene's BVH (host side) and device copy, for benchmarks.
  const BvhScene& bvh() const { return *bvh_; }
  DeviceScene& device() { return *device_; }
  /// the realtime rgb path's device side (after a first rgb frame on the GPU), for benchmarks.
  DeviceRealtime& device_realtime() { return *device_realtime_; }
  /// the realtime rgb path's host side (after a first rgb frame on the GPU), for benchmarks:
  /// how long the host's part of the media took (media_build_ms, media_build_times).
  RealtimeFrameData& realtime_frame() { return *realtime_; }
  /// the pathtraced tier's device side (after a first pathtraced frame on the GPU), for
  /// benchmarks.
  DevicePath& device_path() { return *device_path_; }

  /// whether Render fills RenderedFrame::radiance beside the rgb (default true); off, a
  /// consumer that reads only the rgb and depth saves its copy back (3.7 MB at 640x480) and
  /// the radiance is left empty. a realtime frame's radiance is also left out when the view
  /// does not want it (CameraView::want_radiance); the pathtraced tier fills it either way.
  void set_radiance_output(bool on) { radiance_output_ = on; }
  bool radiance_output() const { return radiance_output_; }

  /// the device's drop culling (null until a frame with drops culled them on the device; benchmarks
  /// read its last Run's times, DeviceStreakCull::run_ms and stage_ms).
  const DeviceStreakCull* device_drop_cull() const { return drop_cull_.get(); }
  /// host milliseconds of the last rgb frame on the GPU before its device work was queued:
  /// the BVH's instances, the frame's preparation (RealtimeFrameData::Prepare) and any sky
  /// upload (benchmarks); without the late streaks (last_late_streaks_ms).
  double last_prepare_ms() const { return prepare_ms_; }
  /// host milliseconds the last realtime rgb frame spent making its late streaks while the GPU
  /// worked (RealtimeFrameData::PrepareStreaks; 0 without late streaks; benchmarks).
  double last_late_streaks_ms() const { return late_streaks_ms_; }
  /// host milliseconds from the start of the last realtime rgb frame's Render to the start of
  /// its late streaks (0 without late streaks; benchmarks).
  double last_late_streaks_start_ms() const { return late_streaks_start_ms_; }

  /// the GPU's pinhole form of `view` (without the ray tables a camera with lens distortion or
  /// motion needs: Render adds them, camera_rays.h).
  static PinholeCamera PinholeOf(const CameraView& view);

 private:
  // the realtime tier's rgb, radiance and depth on the GPU (cuda_realtime.h) under `effects`;
  // `camera`: the view's camera with its ray tables
  // on the device; t0: when Render began (last_prepare_ms).
  void RenderRgb(const WorldSnapshot& snapshot, const EffectsFrame* effects, const CameraView& view,
                 const PinholeCamera& camera, std::chrono::steady_clock::time_point t0,
                 RenderedFrame* out);
  // the late streaks of a realtime frame: PrepareStreaks of the frame's
  // `snapshot`, `effects` and `view` (referenced: they outlive the Render that calls it), then
  // their fields into the device's frame (RealtimeFrameData::StreakFields); times itself
  // (last_late_streaks_ms) and its start from t0, when Render began (last_late_streaks_start_ms).
  DeviceRealtime::StreaksFn LateStreaks(const WorldSnapshot& snapshot, const EffectsFrame* effects,
                                        const CameraView& view,
                                        std::chrono::steady_clock::time_point t0);
  // sets realtime_'s device drop culler: DeviceStreakCull (drop_cull_) on the device's stream
  void SetDeviceDropCuller();
  // after a realtime frame whose drops DeviceStreakCull::Queue culled (cull_queued_): its
  // counts read (DeviceStreakCull::Finish: the culled rain into realtime_, or its ConfigError)
  void FinishDropCulling();
  // the pathtraced tier's rgb, radiance and depth: the paths on the GPU (cuda_path.h), the
  // denoiser and film on the host (path_frame.h's FinishPathFrame).
  // `camera`: the view's camera with its ray tables on the device (Render's).
  void RenderPathtraced(const WorldSnapshot& snapshot, const EffectsFrame* effects,
                        const CameraView& view, const PinholeCamera& camera,
                        std::chrono::steady_clock::time_point t0, RenderedFrame* out);
  // the scene-constant realtime data (materials, textures) and the sky's arrays on the device
  // (once, and the sky again when it changes): both tiers' rgb read them.
  void UploadRealtime();
  // the host's share of a frame's work (the output copies) over pool_, or serially.
  ParallelFn HostParallel();

  SceneDescription scene_;
  std::unique_ptr<BvhScene> bvh_;
  std::unique_ptr<DeviceScene> device_;
  std::unique_ptr<RealtimeFrameData> realtime_;
  std::unique_ptr<DeviceRealtime> device_realtime_;
  std::unique_ptr<DevicePath> device_path_;
  std::unique_ptr<Denoiser> denoiser_;        // the pathtraced tier's, when its settings denoise
  std::unique_ptr<EmitterSampler> emitters_;  // the pathtraced tier's emissive geoms
  std::unique_ptr<PathEmitterHost> emitter_host_;  // as the path kernels take them
  bool emitters_uploaded_ = false;
  const SkyModel* sampling_sky_ = nullptr;  // the sky whose sampling tables the device holds
  uint64_t sampling_generation_ = 0;
  SkySamplingPod sky_sampling_;       // their device copy
  PathBuffers path_buffers_;          // the pathtraced frame's outputs on the host
  MediaScene path_media_;             // the pathtraced frame's media (their device copy:
                                      // DevicePath::UploadMedia)
  EffectsFrame path_effects_;         // the frame's effects without media (EffectsWithoutMedia)
  std::unique_ptr<ThreadPool> pool_;  // the host's sky terms
  std::unique_ptr<DeviceStreakCull> drop_cull_;  // the device's drop culling
  bool cull_queued_ = false;  // the frame's drops queued on drop_cull_, not yet Finished
  // the media volumes' shadow rays (RealtimeFrameData::PrepareMedia) over bvh_ and device_
  std::unique_ptr<CudaRayQuery> media_query_;
  CameraRayTables camera_rays_;  // the frame's camera's ray tables (their device copies:
                                 // DeviceScene::UploadCameraRays)
  bool realtime_uploaded_ = false;
  // the sky volume generation whose arrays the device holds (RealtimeFrameData::sky_generation)
  bool sky_uploaded_ = false;
  uint64_t sky_generation_ = 0;
  double prepare_ms_ = 0;
  double late_streaks_ms_ = 0;
  double late_streaks_start_ms_ = 0;
  bool radiance_output_ = true;
  int64_t gpu_frames_ = 0;
};

}  // namespace penumbra::cuda
