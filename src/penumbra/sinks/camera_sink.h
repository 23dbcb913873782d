#pragma once
// the cameras of a run as a pipeline sink (pipeline/sink.h): which steps each camera captures
// (sensors/sensor_schedule.h), exposures that need a later snapshot (motion blur, rolling
// shutter; sensors/camera_imager.h), image formation per camera on the sink's render thread,
// and every image file through the asynchronous frame writer (output/async_frame_writer.h):
//
// - DIR/<camera>/{rgb,depth,segmentation}/NNNNNN.png, frames.csv, intrinsics.json
//   (output/camera_writer.h)
// - DIR/<camera>/range/NNNNNN.png: 16-bit range along the pixel ray, mm, 0 = no hit
// - DIR/<camera>/normals/NNNNNN.png: 8-bit rgb (n_O + 1) / 2 * 255 of the unit normal facing the
//   camera in the optical frame
// - DIR/<camera>/instance_segmentation/NNNNNN.png: 16-bit body index + 1, 0 = background
// - DIR/<camera>/semantic_segmentation/NNNNNN.png: 16-bit semantic class id, 0 = none
// - DIR/camera_info.yaml, DIR/camera_info.json: ROS CameraInfo per camera (output/camera_info.h)
// - DIR/semantic_classes.json: {class name: id} of the world file's `semantic_classes:`
//
// depth/ holds the depth sensor's measurement (with depth_noise) or the exact z-depth; all other
// images are exact. frames.csv time/pose: the capture instant, or mid-exposure (sub-frame n/2)
// when the frame uses motion blur or a rolling shutter.
//
// stopping: when the renderer's stop request (Renderer::set_stop_request) ends a render (the
// pathtraced tier stops between samples), that frame and any rendered after it are dropped:
// no image, no frames.csv row.
//
// a camera's first black frame (every rgb byte <= 2) logs one warning naming the camera, the
// frame and the likely cause: an exposure too dark for the scene (radiance above 0), a world
// without light (no lit light, black sky, no emissive material), or no light reaching the
// camera (inside geometry, or facing only unlit surfaces). docs/cameras.md ("Black frames").
//
// timing: camera c fires its frame k at the first physics step whose time is >= k / rate_hz, on
// the step count, so frames never drift however the rate and timestep relate; a camera faster
// than physics renders once per step. the effects a camera sees (scene/effects_frame.h) are
// evaluated on the loop thread when its frame is captured (in step order, as the effects
// engine wants) and travel beside the snapshot; rendering runs on the sink's own thread in
// capture order, so the images do not depend on thread timing.

#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "penumbra/output/async_frame_writer.h"
#include "penumbra/pipeline/sink.h"
#include "penumbra/pipeline/sink_worker.h"
#include "penumbra/render/renderer.h"
#include "penumbra/scene/effects_frame.h"
#include "penumbra/sensors/camera_imager.h"
#include "penumbra/sensors/sensor_schedule.h"
#include "penumbra/sinks/frame_buffer_pool.h"
#include "penumbra/world/world_config.h"

namespace penumbra {

/// the effects a viewer at `p_W` (world frame, m) sees at `snapshot` (e.g.
/// EffectsStage::Evaluate); null = clear conditions. called on the loop thread only.
using ViewerEffects = std::function<std::shared_ptr<const EffectsFrame>(
    const WorldSnapshot& snapshot, const Eigen::Vector3d& p_W)>;

/// the span of sim time camera `spec`'s frames need after their capture (0: rendered at once).
double CaptureSpanSec(const CameraSpec& spec, const CameraSensorConfig& config);

/// which steps must be handed over as end-of-exposure snapshots.
class ShutterSchedule {
 public:
  ShutterSchedule(const SceneDescription& scene, const WorldConfig& world);
  /// true if an exposure started earlier ends at or before `time_sec` (consumes those ends).
  bool Due(double time_sec);
  /// records the exposures of `cameras` starting at `time_sec`.
  void Add(double time_sec, const std::vector<int>& cameras);

 private:
  std::vector<double> span_;
  std::multiset<double> ends_;
};

/// settings of a CameraSink.
struct CameraSinkOptions {
  /// captured snapshots waiting for the render thread before the loop blocks, >= 1.
  int render_queue = 4;
  /// the frame writer's queue and threads.
  AsyncFrameWriterOptions writer;
  /// called on the render thread after each captured snapshot is rendered with its sim time
  /// and the frames rendered so far (e.g. a progress bar); may be empty.
  std::function<void(double time_sec, int64_t frames)> on_rendered;
  /// the names of the cameras to render (empty = every camera of the scene). the others are
  /// neither rendered nor written (no folder, no camera_info entry); every camera keeps its
  /// index in the scene (its noise streams), so a selected camera's frames do not depend on
  /// the selection.
  std::vector<std::string> cameras;
  /// receives every frame as it is completed, with its raw images (the buffers the files are
  /// encoded from), on the render thread, in capture order per camera, before the frame goes
  /// to the writer (e.g. a bridge publishing images; command/run_bridge.h). may be empty;
  /// when set, each frame is copied once into the shared object.
  std::function<void(const std::shared_ptr<const CameraFrame>& frame)> on_frame;
  /// the step the current episode started at (Simulation::controller_episode_start: the last
  /// `reset`), read on the loop thread at every step; empty = one episode. when it changes,
  /// the exposures open end at the last snapshot, every camera's schedule restarts on the
  /// episode's clock and its imager starts over (noise keyed by the frame's index within the
  /// episode, auto exposure from its start); written frame indices go on increasing.
  std::function<int64_t()> episode_start;
};

/// every camera of `scene`. the render thread is the only user of `renderer`.
class CameraSink : public Sink {
 public:
  /// registers every camera with the frame writer (folders, intrinsics.json, frames.csv
  /// header), makes the extra output folders and writes camera_info.yaml/json and
  /// semantic_classes.json. `timestep_sec` is the physics timestep (the schedules count
  /// steps). `scene`, `renderer` must outlive the sink; `effects` may be empty (clear
  /// conditions).
  /// @throws ConfigError for bad camera names or sensor settings, or (key "--cameras") a name
  ///         in CameraSinkOptions::cameras that is not a camera of the scene; Error if files
  ///         cannot be written.
  CameraSink(const SceneDescription& scene, const WorldConfig& world, double timestep_sec,
             Renderer* renderer, const std::string& output_dir, ViewerEffects effects,
             CameraSinkOptions options = {});
  ~CameraSink() override;

  /// starts the render thread. a loop that starts at a later step (a replay from --from)
  /// captures the frames a run from step 0 captures from that step on, with the same indices.
  void OnStart(const LoopStart& start) override;
  /// kPoses at steps where a camera fires or an exposure ends.
  SnapshotContent Wants(int64_t step, double time_sec) override;
  /// hands the snapshots this sink asked for (with each capturing camera's effects) to the
  /// render thread; others are ignored.
  void OnSnapshot(const std::shared_ptr<const WorldSnapshot>& snapshot) override;
  /// completes the pending exposures with the last snapshot (not after an error), waits for
  /// the render thread and the writer. @throws Error the first write error not yet reported.
  void OnFinish(const LoopFinish& finish) override;

  /// replaces CameraSinkOptions::on_frame (before the loop starts).
  void set_on_frame(std::function<void(const std::shared_ptr<const CameraFrame>& frame)> on_frame) {
    options_.on_frame = std::move(on_frame);
  }

  /// loop thread, while the loop runs: blocks until every snapshot handed over so far is
  /// rendered (frames whose exposure ended by then completed and given to on_frame).
  void Drain() { worker_.Drain(); }

  /// frames.csv rows written per camera (read after OnFinish).
  std::map<std::string, int64_t> FramesWritten() const { return writer_.FramesWritten(); }
  /// wall time spent rendering and forming images, s (read after OnFinish).
  double render_sec() const { return render_sec_; }
  /// the part of render_sec() spent on each camera's first frame, s: the renderer's set-up on
  /// first use (textures, scene upload, device context) falls there (read after OnFinish).
  double render_first_frames_sec() const { return render_first_frames_sec_; }
  /// the part of render_sec() spent inside Renderer::Render, s; the rest is the camera model
  /// (CameraImager: exposure, noise, develop, copies) (read after OnFinish).
  double renderer_sec() const;
  /// the writer threads' PNG encoding and file writing, s (read after OnFinish).
  PngWriteTimes png_times() const { return writer_.PngTimes(); }

 private:
  struct Pending {
    int camera;
    int64_t frame;
    int64_t noise_frame;  // the frame's index within its episode
    std::shared_ptr<const WorldSnapshot> start;
    std::shared_ptr<const EffectsFrame> effects;
    double end_time;
  };
  struct Capture {
    int64_t step = -1;
    std::vector<int> cameras;
    std::vector<int64_t> frames;
    std::vector<int64_t> noise_frames;  // per camera: the frame's index within the episode
  };
  // loop thread: a new episode starts at step `start`; the loop is at `step`
  void StartEpisode(int64_t start, int64_t step);
  // render thread
  void Render(const std::shared_ptr<const WorldSnapshot>& snapshot, const Capture& capture,
              const std::vector<std::shared_ptr<const EffectsFrame>>& effects);
  void CompletePending(bool with_last);
  void Complete(const Pending& p, const WorldSnapshot* end);

  const SceneDescription& scene_;
  Renderer* renderer_;
  RenderSettings render_;  // the world's exposure settings (for the black-frame warning)
  ViewerEffects effects_;
  CameraSinkOptions options_;
  std::function<void(std::exception_ptr)> report_error_;
  // the written frames' images, reused by the next frames (declared before the writer, whose
  // threads return frames into it until the writer is destroyed)
  FrameBufferPool buffers_;
  AsyncFrameWriter writer_;
  // loop thread
  SensorSchedule schedule_;  // on the current episode's clock
  double timestep_sec_;
  int64_t episode_start_ = 0;
  bool later_episode_ = false;       // a reset started an episode
  std::vector<int64_t> next_frame_;  // per scene camera: the index of its next frame
  std::vector<int64_t> frame_base_;  // per scene camera: frame = base + index in episode
  ShutterSchedule shutters_;
  std::vector<SensorFiring> due_;
  std::vector<char> selected_;  // per scene camera: rendered (CameraSinkOptions::cameras)
  std::optional<Capture> capture_;
  // render thread
  std::vector<CameraImager> imagers_;
  // what the imagers are made of (a new episode makes them anew)
  std::vector<CameraSensorConfig> imager_configs_;
  double renderer_sec_before_ = 0;  // renderer time of the imagers of earlier episodes
  // per scene camera: the last frame's images that are not handed to the writer (the renderer's
  // radiance, rgb and depth, the imager's radiance), reused by the camera's next frame
  std::vector<CameraImages> scratch_;
  std::vector<char> warned_black_;  // per scene camera: its black-frame warning was logged
  std::vector<double> span_;
  std::deque<Pending> pending_;
  std::shared_ptr<const WorldSnapshot> last_;
  double render_sec_ = 0;
  double render_first_frames_sec_ = 0;
  std::vector<char> rendered_once_;  // per scene camera: its first frame was captured
  int64_t frames_ = 0;
  SinkWorker worker_;
};

}  // namespace penumbra
