#pragma once
// the output sinks of a run, built once for `penumbra run` (run/runner.cc) and `penumbra
// replay` (replay/kinematic/replay_runner.cc): the cameras (sinks/camera_sink.h), the sensors
// (sinks/sensor_sink.h), trajectory.csv (output/trajectory_sink.h), the world's `metrics:`
// (metrics/metrics_sink.h), the fall detector (metrics/fall_detector.h) and the progress bar,
// plus the run.json fields they share. the
// callers add what differs (the run log recorder, the replay's manifest object, the source)
// and the ManifestSink last.

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "penumbra/metrics/fall_detector.h"
#include "penumbra/metrics/metrics_sink.h"
#include "penumbra/output/progress.h"
#include "penumbra/output/run_manifest.h"
#include "penumbra/output/trajectory_sink.h"
#include "penumbra/pipeline/sim_loop.h"
#include "penumbra/session/session.h"
#include "penumbra/sinks/camera_sink.h"
#include "penumbra/sinks/sensor_sink.h"

namespace penumbra {

/// what differs between the users of RunOutputs.
struct RunOutputsOptions {
  /// the sim time the loop ends at, s (the progress bar's total).
  double end_time_sec = 0;
  /// draw a progress bar / log progress lines (ProgressOptions::Mode::kAuto) or nothing.
  bool progress = false;
  /// the pathtraced tier's sample-pass lines: ProgressOptions::pass_interval_sec (--progress-
  /// interval), s.
  double progress_pass_interval_sec = 1.0;
  /// what the snapshots give the metrics sink: kDynamics for live physics, kKinematic for a
  /// replay that only moves the bodies.
  MetricsMode metrics_mode = MetricsMode::kDynamics;
  /// the cameras to render (CameraSinkOptions::cameras; empty = all).
  std::vector<std::string> cameras;
  /// snapshots waiting for the render thread before the loop blocks
  /// (CameraSinkOptions::render_queue, >= 1): 1 for a live run at real-time pacing, so that
  /// a frame shows what the run did at most one render time ago.
  int render_queue = 4;
  /// receives every image file the cameras write (AsyncFrameWriterOptions::on_image), e.g.
  /// the run log's sensor records; may be empty.
  CameraImageCallback on_image;
};

/// the output sinks of a run over `session`'s simulation, scene, renderer and effects.
/// neither copied nor moved (the sinks keep references to each other's callbacks).
class RunOutputs {
 public:
  /// builds the sinks in this order: cameras, sensors, trajectory, metrics (when `world` has
  /// `metrics:`), falls (when a robot has a free joint), then the progress reporter. `world` is the
  /// world the session was built from, with the run's overrides applied; `session` and `world` must
  /// outlive this object.
  /// @throws ConfigError from the sinks (bad camera or sensor settings, an unknown --cameras
  ///         name, a metric name that matches nothing); Error if an output cannot be created.
  RunOutputs(Session& session, const WorldConfig& world, const std::filesystem::path& out_dir,
             RunOutputsOptions options);
  RunOutputs(const RunOutputs&) = delete;
  RunOutputs& operator=(const RunOutputs&) = delete;
  /// detaches the progress reporter from the session's renderer.
  ~RunOutputs();

  CameraSink& cameras() { return *cameras_; }
  SensorSink& sensors() { return *sensors_; }
  /// the metrics sink, or nullptr when the world has no `metrics:`.
  MetricsSink* metrics() { return metrics_.get(); }
  /// the fall detector, or nullptr when no robot of the world has a free joint.
  FallSink* falls() { return falls_.get(); }

  /// adds the sinks to `loop` in the order sensors, cameras, trajectory, metrics, falls (the caller
  /// adds its own sinks after them, the ManifestSink last).
  void AddTo(SimLoop* loop);

  /// on the loop's finish (from the ManifestSink's describe callback, after every other
  /// sink's OnFinish): ends the progress bar and adds "sensors_<kind>_sec", "render_sec"
  /// with its parts "render_first_frames_sec" (each camera's first frame: the renderer's
  /// set-up on first use) and "render_renderer_sec" (inside Renderer::Render; the rest is the
  /// camera model), "png_encode_sec" and "png_write_sec" (the frame writer's threads) to
  /// `timings`.
  void Finish(std::map<std::string, double>* timings);

  /// run.json's shared fields: `world_file`, seed, the versions, `command_line`, the sim
  /// time reached, `interrupted`, `timings`, `peak_rss_mib`, frames written per camera, the
  /// adversity label, effects, agents and the metrics summary. call after Finish.
  RunManifest Describe(const std::string& world_file, const std::vector<std::string>& command_line,
                       double sim_time_sec, bool interrupted,
                       const std::map<std::string, double>& timings, double peak_rss_mib) const;

 private:
  Session& session_;
  const WorldConfig& world_;
  std::optional<ProgressReporter> progress_;  // made once the sinks are set up
  std::unique_ptr<CameraSink> cameras_;
  std::unique_ptr<SensorSink> sensors_;
  std::unique_ptr<TrajectorySink> trajectory_;
  std::unique_ptr<MetricsSink> metrics_;
  std::unique_ptr<FallSink> falls_;  // null when no robot has a free joint
};

}  // namespace penumbra
