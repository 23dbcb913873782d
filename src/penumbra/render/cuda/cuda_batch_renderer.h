#pragma once
// batch rendering on the GPU (docs/gpu.md "Batch rendering"): the cameras of
// one world, and the cameras of N independent worlds (N sessions in one process), rendered by
// one kernel launch into one device buffer; the images copied back in one pinned transfer per
// batch on a second stream, overlapped with the next batch's kernel, or left on the device for
// a consumer on the GPU (the device-pointer API below). the images are the ground truth of each
// pixel-centre ray (depth, segmentation, instance and semantic segmentation, range, normals) and
// the realtime tier's rgb (BatchOutputs::rgb: each realtime stage launched once over all cameras,
// RealtimeBatch; its depth is the realtime path's), the same bits as the same camera in a batch
// of its own and as CudaRenderer rendering that camera alone. the rgb and depth of a camera of a
// world whose effects have particles or media (PerCameraEffects: rain, snow, sparks, fog, haze,
// dust, smoke, fire; their streaks and froxels are the camera's own) are rendered by that
// world's CudaRenderer, camera by camera (the single-frame pipeline, RealtimeFrameData and
// DeviceRealtime::Render), and copied into the batch's buffer after the batch's kernels.
//
//   BatchRenderer batch({.width = 128, .height = 128, .max_cameras = 1024});
//   const int house = batch.AddWorld(session.scene());
//   batch.UpdateWorld(house, session.sim().Snapshot());
//   std::vector<BatchCamera> cams = ...;               // batch.CameraOf(house, view)
//   const int64_t t = batch.Submit(cams);              // returns at once
//   ... step the worlds, UpdateWorld, Submit(t + 1) ... // overlaps t's copy back
//   const BatchImages img = batch.Wait(t);             // host images of batch t
//   const float* depth_of_camera_3 = img.depth(3);
//
// threading: one thread at a time (not thread-safe).

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "penumbra/core/thread_pool.h"
#include "penumbra/render/cuda/batch_layout.h"
#include "penumbra/render/cuda/cuda_batch_kernels.h"
#include "penumbra/render/cuda/cuda_kernels.h"
#include "penumbra/render/cuda/cuda_realtime.h"
#include "penumbra/render/cuda/cuda_renderer.h"
#include "penumbra/render/frame/bvh_scene.h"
#include "penumbra/render/frame/camera_rays.h"
#include "penumbra/render/frame/realtime_frame.h"
#include "penumbra/render/render_settings.h"
#include "penumbra/render/renderer.h"
#include "penumbra/scene/effects_frame.h"
#include "penumbra/scene/scene_description.h"
#include "penumbra/scene/world_snapshot.h"

namespace penumbra::cuda {

/// what a BatchRenderer renders and where the images go.
struct BatchConfig {
  int width = 128;         ///< every camera's image width, px
  int height = 128;        ///< every camera's image height, px
  int max_cameras = 1024;  ///< most cameras in one batch (sizes the buffers), 1 to 65535
  BatchOutputs outputs;    ///< default depth and segmentation
  BatchCopy copy = BatchCopy::kPinned;
  /// the ray queries the rgb worlds' static maps (sky irradiance volume, shelter map) are
  /// traced through (CudaRenderer's `statics_query`); empty: BvhRayQuery over the batch's host
  /// threads. a batch camera gives CudaRenderer's bits for the same view when both take the
  /// same: StaticMapsQueryFactory() (render/backends/renderer_factory.h) for a renderer made by
  /// MakeRenderer.
  RayQueryFactory statics_query;
};

/// the images of one batch, on the host (BatchRenderer::Wait) or on the device
/// (BatchRenderer::DeviceImages): camera k's image of an output is width x height row-major
/// values of BatchPlaneBytes bytes (4; normals 12, rgb 3) (BatchLayout), null if that output
/// is off.
struct BatchImages {
  const uint8_t* base = nullptr;  ///< the batch's buffer (host or device pointer)
  const BatchLayout* layout = nullptr;
  int cameras = 0;         ///< cameras in the batch
  bool on_device = false;  ///< base is a device pointer
  /// camera k's depth (m, 0 = miss) / range (m) / segmentation (geom id, -1 = miss) /
  /// instance (body id) / semantic class / normals (width x height x 3 floats, the unit
  /// normal facing the camera in its optical frame, 0 0 0 = miss, as RenderedFrame::normal_O) /
  /// rgb (width x height x 3 sRGB bytes, row-major, as RenderedFrame::rgb); null if not
  /// rendered.
  const float* depth(int k) const { return Plane<float>(BatchPlane::kDepth, k); }
  const float* range(int k) const { return Plane<float>(BatchPlane::kRange, k); }
  const int32_t* geom_id(int k) const { return Plane<int32_t>(BatchPlane::kSegmentation, k); }
  const int32_t* body_id(int k) const { return Plane<int32_t>(BatchPlane::kInstance, k); }
  const int32_t* semantic(int k) const { return Plane<int32_t>(BatchPlane::kSemantic, k); }
  const float* normal_O(int k) const { return Plane<float>(BatchPlane::kNormal, k); }
  const uint8_t* rgb(int k) const { return Plane<uint8_t>(BatchPlane::kRgb, k); }

 private:
  template <typename T>
  const T* Plane(BatchPlane p, int k) const {
    if (!base || !layout->has(p) || k < 0 || k >= cameras) return nullptr;
    return reinterpret_cast<const T*>(base + layout->image_offset(p, cameras, k));
  }
};

/// batch rendering (see the file comment).
class BatchRenderer {
 public:
  /// @throws Error for a bad config (BatchLayout) or if the CUDA runtime fails (no device:
  ///         check ProbeCudaDevice first).
  explicit BatchRenderer(const BatchConfig& config);
  ~BatchRenderer();

  /// adds a world (one session's scene, copied) and builds its BVH on the host and the
  /// device; returns its index for BatchCamera::world (0, 1, ...). bodies are at the
  /// identity until UpdateWorld. with rgb, `settings` are its realtime frames' (film, seed,
  /// anisotropy; as CudaRenderer's) and its materials and textures go to the device; a world's
  /// cameras need an UpdateWorld before their first Submit.
  /// @throws Error as BvhScene or RealtimeFrameData, or if the CUDA runtime fails.
  int AddWorld(const SceneDescription& scene, const RenderSettings& settings = RenderSettings());
  /// worlds added.
  int num_worlds() const { return static_cast<int>(worlds_.size()); }
  /// poses world `world`'s bodies from `snapshot` (its instances' transforms; the static BVH is
  /// rebuilt only if a static body moved; with rgb also its lights, geoms and sky volume,
  /// RealtimeFrameData::PoseWorld) under the `effects` of that instant (null: none; light
  /// scales, extra lights, a moved or scaled sky, surface wetness, particles, media; they apply
  /// to the rgb of every camera of this world until the next UpdateWorld; the ground-truth
  /// images do not depend on them). with rgb and PerCameraEffects, the snapshot and effects are
  /// copied for the world's cameras rendered alone (Submit), the world's CudaRenderer (same
  /// scene and settings, realtime tier) made on the first such frame. waits for the kernels
  /// already submitted (they read the transforms), not for their copies back.
  /// @throws Error for a bad index or snapshot (BvhScene::Update), or as CudaRenderer's
  ///         constructor or RealtimeFrameData::PoseWorld (effects out of range).
  void UpdateWorld(int world, const WorldSnapshot& snapshot, const EffectsFrame* effects = nullptr);

  /// renders `cameras` (BatchLayout::Check) in one kernel launch (with rgb: one launch of each
  /// realtime stage, the cameras' exposures from their row sums included) and starts the copy
  /// back (BatchCopy); returns the batch's ticket (0, 1, ...). the images of ticket t stay
  /// readable until ticket t + 2 is submitted. the ray tables the cameras name (CameraOf) are
  /// copied to the device with the batch. with rgb, a camera whose world's last UpdateWorld had
  /// PerCameraEffects gets its rgb and depth from that world's CudaRenderer rendering its view
  /// (view_table) alone, while the batch's kernels run: a batch with such cameras returns once
  /// they are rendered (CudaRenderer::Render blocks) and their images are queued into the
  /// batch's buffer (before ready_event; kernel_ms counts the wait); a batch without them
  /// returns at once. if one of those renders throws, Submit throws (no ticket is returned).
  /// @throws Error for bad cameras (naming the camera; a camera whose tables are another
  ///         renderer's, or whose row tables are older than a CameraOf call made after a
  ///         Submit; with rgb, a camera of a world with PerCameraEffects without a view of this
  ///         renderer's CameraOf of the current generation), with rgb for a camera of a world
  ///         not yet updated, as CudaRenderer::Render, or if the CUDA runtime fails.
  int64_t Submit(std::span<const BatchCamera> cameras);
  /// blocks until batch `ticket` is on the host and returns its host images (with
  /// BatchCopy::kNone: until its kernel finished; the images' base is then null).
  /// @throws Error if the ticket was not submitted or its slot was reused (t + 2 submitted).
  BatchImages Wait(int64_t ticket);

  /// the device-pointer API: batch `ticket`'s images in device memory (BatchImages with
  /// on_device true), readable by work that runs after ready_event(ticket) (e.g. enqueued on
  /// stream() after Submit, or on another stream after cudaStreamWaitEvent(s,
  /// ready_event(ticket))) and done before ticket + 2 is submitted (whose kernel overwrites
  /// the buffer). does not wait.
  /// @throws Error as Wait.
  BatchImages DeviceImages(int64_t ticket) const;
  /// the cudaEvent_t (as void*) recorded after batch `ticket`'s kernel.
  void* ready_event(int64_t ticket) const;
  /// the cudaStream_t (as void*) the kernels run on.
  void* stream() const { return device_->stream(); }
  /// milliseconds batch `ticket`'s kernel took (CUDA events; call after Wait(ticket)); with
  /// rgb all its kernels.
  double kernel_ms(int64_t ticket) const;
  /// host milliseconds Submit of batch `ticket` spent rendering the cameras of worlds with
  /// PerCameraEffects alone (0 without such cameras; benchmarks).
  /// @throws Error as Wait.
  double alone_ms(int64_t ticket) const;
  /// how many cameras of batch `ticket` were rendered alone (PerCameraEffects).
  /// @throws Error as Wait.
  int alone_cameras(int64_t ticket) const;
  /// with rgb: the GPU time of batch `ticket`'s realtime stages (call after Wait(ticket)).
  /// @throws Error as Wait, or if the batch renders no rgb.
  RealtimeBatchTimes stage_ms(int64_t ticket) const;

  const BatchLayout& layout() const { return layout_; }
  /// world `world`'s BVH on the host (tests, build times).
  const BvhScene& bvh(int world) const { return *worlds_.at(world)->bvh; }

  /// the batch camera of `view` in world `world`, with its camera_index, frame_index, pixel
  /// spread and white balance. a camera with lens distortion or motion gets ray tables
  /// (camera_rays.h, the CPU backend's camera model) kept by this renderer and named in the
  /// BatchCamera: the undistortion table of its intrinsics for the renderer's lifetime (one per
  /// distinct intrinsics: 8 bytes a pixel), a moving camera's per-row poses (48 bytes a row)
  /// until the first CameraOf call after a Submit (so make a moving camera's BatchCamera again
  /// for each frame; a batch may be submitted again before that). a pinhole camera that does
  /// not move names no tables and serves any BatchRenderer. every camera also names a copy of
  /// `view` (view_table, kept as the row tables are), which a world with PerCameraEffects
  /// renders alone: such a world's cameras must come from this renderer's CameraOf.
  /// @throws ConfigError as Camera for bad intrinsics or motion.
  BatchCamera CameraOf(int world, const CameraView& view);

 private:
  struct World {
    SceneDescription scene;
    std::unique_ptr<BvhScene> bvh;
    std::unique_ptr<DeviceScene> device;
    // with rgb: the realtime frames' host data and device arrays, and the frame (device
    // pointers) of the last UpdateWorld, its camera set per batch camera
    std::unique_ptr<RealtimeFrameData> realtime;
    std::unique_ptr<DeviceRealtime> device_realtime;
    RealtimeFrameView frame;
    bool posed = false;
    uint64_t sky_generation = 0;
    bool sky_uploaded = false;
    // with rgb and PerCameraEffects in the last UpdateWorld: that frame's snapshot and effects
    // and the renderer that draws each of the world's cameras alone (made once, then kept)
    RenderSettings settings;
    bool alone = false;
    WorldSnapshot snapshot;
    EffectsFrame effects;
    std::unique_ptr<CudaRenderer> single;
  };
  // the slot of `ticket` (BatchTickets::SlotOf); throws Error unless the ticket's images are
  // still readable (one of the last BatchTickets::kSlots submitted).
  int CheckedSlot(int64_t ticket) const;
  // `batch` with its cameras' ray tables copied to `slot`'s device buffer and their xy and
  // rows pointing there (in patched_); `batch` itself when no camera has tables.
  std::span<const BatchCamera> WithRayTables(std::span<const BatchCamera> batch, int slot);
  // the realtime rgb of `cameras` into `buffer` (the slot's device buffer) on `stream`.
  void LaunchRgb(std::span<const BatchCamera> cameras, int slot, void* stream, uint8_t* buffer);
  // the cameras of `cameras` whose worlds render them alone (PerCameraEffects) rendered by their
  // worlds' CudaRenderer and their rgb and depth copied into `buffer` at their places on
  // `stream`; their count and host milliseconds into `slot`'s alone_count_ and alone_ms_.
  void RenderAlone(std::span<const BatchCamera> cameras, int slot, void* stream, uint8_t* buffer);
  // throws for a camera of a world that renders alone without a view of this renderer's current
  // generation (Submit's checks).
  void CheckAloneViews(std::span<const BatchCamera> cameras) const;

  BatchLayout layout_;
  std::unique_ptr<BatchDevice> device_;
  std::vector<std::unique_ptr<World>> worlds_;
  std::vector<SceneView> views_;  // each world's device arrays, as the kernel reads them
  std::vector<int> counts_;       // cameras of the batch in each slot
  std::vector<int> alone_count_;  // of them, rendered alone (RenderAlone), per slot
  std::vector<double> alone_ms_;  // and the host milliseconds that took, per slot
  // the images of the cameras rendered alone (RenderAlone's staging, one per camera)
  std::vector<RenderedFrame> alone_frames_;
  BatchTickets tickets_;
  // with rgb: the stages' working buffers, sized for the most lights and the mirror layer of
  // the worlds, and the pool of the sky volume's updates
  std::unique_ptr<RealtimeBatch> realtime_;
  int realtime_lights_ = -1;
  bool realtime_mirror_ = false;
  std::unique_ptr<ThreadPool> pool_;
  std::vector<RealtimeFrameView> frames_;  // one batch's frames (LaunchRgb)
  std::vector<RealtimeBatchFilm> films_;
  // the ray tables of cameras with lens distortion or motion (CameraOf): the xy tables by
  // intrinsics, the row tables of the current generation; a batch's tables end to end and
  // its cameras pointing to their device copy (Submit)
  struct XyTable {
    CameraIntrinsics intrinsics;
    std::vector<float> xy;
  };
  RayQueryFactory statics_query_;  // BatchConfig::statics_query
  uint64_t id_;                    // tables_owner of this renderer's cameras
  CameraRayTables ray_tables_;
  std::vector<XyTable> xy_tables_;
  std::vector<std::vector<float>> rows_tables_;
  std::vector<CameraView> camera_views_;  // the views of CameraOf, of the current generation
  int64_t rows_generation_ = 1;
  bool submitted_since_rows_ = false;
  std::vector<float> table_floats_;
  std::vector<BatchCamera> patched_;
};

}  // namespace penumbra::cuda
