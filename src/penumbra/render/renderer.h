#pragma once
// the renderer interface: turns a WorldSnapshot seen from one camera into images.
// implementations never touch the physics engine, so a recorded run can be
// re-rendered without it. MakeRenderer (render/backends/renderer_factory.h) builds the one of
// RenderSettings::backend (Embree: render/cpu/embree_renderer.h).

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>

#include "penumbra/core/image.h"
#include "penumbra/render/camera/camera.h"
#include "penumbra/render/render_settings.h"
#include "penumbra/scene/effects_frame.h"
#include "penumbra/scene/scene_description.h"
#include "penumbra/scene/world_snapshot.h"

namespace penumbra {

/// what to render: a pinhole camera at a pose.
struct CameraView {
  Pose X_WO = Pose::Identity();  ///< optical frame (OpenCV: x right, y down, z forward) in world
  CameraIntrinsics intrinsics;
  CameraOutputs outputs;
  int64_t frame_index = 0;  ///< per-camera frame counter, keys the per-pixel random numbers
  int camera_index = 0;     ///< index in SceneDescription::cameras, keys the random numbers too
  double exposure_time_sec = 0.01;  ///< shutter open time from the snapshot's time (streaks, blur)
  /// optical-frame motion for this render (rolling shutter, motion-blur sub-frames); default
  /// = a camera fixed at X_WO (render/camera/camera.h).
  CameraMotion motion;
  /// near clipping distance, m, as z-depth along the optical axis: geometry nearer than this
  /// is not seen (the role of MuJoCo's znear; no lens focuses this close). it also keeps the
  /// camera's own housing, whose bounding box holds the optical centre, out of every primary
  /// ray's traversal. >= 0.
  double near_m = 0.01;
  /// white balance gains (linear rgb, render/film/white_balance.h) multiplied into the exposure of
  /// each channel when rgb is developed (Film::Develop's wb_gains); ones = none. CameraImager
  /// sets them when they are known before the frame (modes daylight, kelvin) so that the
  /// renderer's rgb is the camera's and is not developed a second time.
  Eigen::Vector3f white_balance_gains = Eigen::Vector3f::Ones();
  /// whether the caller reads RenderedFrame::radiance. false lets a renderer that develops rgb
  /// itself leave the radiance out (CudaRenderer then skips its copy from the device, 3.7 MB at
  /// 640x480); rgb, ev100 and every other image are the same either way. a renderer may still
  /// fill it (the CPU backends do: they develop rgb from it). default true: always filled.
  bool want_radiance = true;
};

/// images of one frame; the ones not requested are left empty.
struct RenderedFrame {
  ImageF radiance;  ///< (H x W x 3) float, linear scene radiance in cd/m^2 per channel, before
                    ///< exposure
  ImageU8 rgb;      ///< (H x W x 3) uint8 sRGB after exposure and tone mapping
  ImageF depth_m;   ///< (H x W x 1) float z-depth along the optical axis in m, 0 = no hit
  ImageI32
      geom_id;  ///< (H x W x 1) MuJoCo geom id of the first hit, -1 = background; never blended
  /// the images below come from the same pixel-centre ray as depth_m (never blended).
  ImageF
      range_m;  ///< (H x W x 1) float distance optical centre -> hit along the ray, m; 0 = no hit
  ImageF normal_O;  ///< (H x W x 3) float unit geometric normal facing the camera, optical frame; 0
                    ///< = no hit
  ImageI32 body_id;  ///< (H x W x 1) SceneDescription body index of the hit geom, -1 = background
  ImageI32 semantic_class;  ///< (H x W x 1) Geom::semantic_class of the hit geom, 0 = background
  double ev100 = 0;         ///< exposure value used for rgb
  int64_t rays = 0;  ///< rays traced for this frame (primary + shadow + secondary), for benchmarks
  /// the stop request (Renderer::set_stop_request) ended this render before its radiance was
  /// complete: rgb and radiance are unfinished and must not be used (the ground-truth images
  /// are complete).
  bool stopped = false;
};

/// how far one Render of the pathtraced tier has got (RenderSettings::samples_per_pixel
/// passes over the image; the tier renders tile by tile, all of a pixel's samples at once, so
/// a pass here is the equivalent count: samples traced / pixels).
struct RenderProgress {
  int camera_index = 0;       ///< CameraView::camera_index of the render
  int64_t frame_index = 0;    ///< CameraView::frame_index of the render
  int64_t samples_done = 0;   ///< pixel samples traced so far
  int64_t samples_total = 0;  ///< width * height * samples_per_pixel
  int passes_done = 0;        ///< samples_done / (width * height), rounded down
  int passes = 0;             ///< samples_per_pixel
};

/// receives RenderProgress: once with passes_done = 0 when a render starts, then once for
/// each pass 1, 2, ..., passes in order (not for a stopped render), each as soon as the thread
/// that called Render sees it done: the callback always runs on that thread, never on a
/// render worker, so passes the workers finish while that thread renders a tile, or after it
/// ran out of tiles, are reported together then.
using RenderProgressCallback = std::function<void(const RenderProgress&)>;

/// renders frames of one scene. not thread-safe: one Render at a time (each call is
/// parallel inside).
class Renderer {
 public:
  virtual ~Renderer() = default;
  /// renders `view` of the world posed by `snapshot` under `effects` into `out`. `effects`
  /// are the adverse conditions this viewer sees at the snapshot's time (media, particles,
  /// light changes; scene/effects_frame.h), null or empty = clear conditions.
  /// @throws Error if the snapshot does not match the scene (body counts differ);
  ///         ConfigError for effects out of range (e.g. a negative light scale).
  virtual void Render(const WorldSnapshot& snapshot, const EffectsFrame* effects,
                      const CameraView& view, RenderedFrame* out) = 0;
  /// Render under clear conditions (no effects).
  void Render(const WorldSnapshot& snapshot, const CameraView& view, RenderedFrame* out) {
    Render(snapshot, nullptr, view, out);
  }

  /// a stop request (e.g. set by a SIGINT handler; null = none, the default). the pathtraced
  /// tier reads it before every sample of every pixel: once it reads non-zero a render ends
  /// within one sample per render thread, with RenderedFrame::stopped set. reading it changes
  /// nothing in the images of a render it does not stop. `stop` must outlive the renderer.
  void set_stop_request(const std::atomic<int>* stop) { stop_request_ = stop; }

  /// progress of the pathtraced tier's renders (see RenderProgressCallback; empty = none, the
  /// default; the realtime tier reports none). reading the progress changes nothing in the
  /// images.
  void set_progress_callback(RenderProgressCallback callback) { progress_ = std::move(callback); }

 protected:
  const std::atomic<int>* stop_request_ = nullptr;
  RenderProgressCallback progress_;
};

/// the checks every backend's Render makes before tracing: one body pose per scene body and a
/// finite near plane >= 0. @throws Error "Render: ..." naming what is wrong.
void CheckRenderInputs(size_t num_scene_bodies, const WorldSnapshot& snapshot,
                       const CameraView& view);

}  // namespace penumbra
