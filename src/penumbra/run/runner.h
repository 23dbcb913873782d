#pragma once
// `penumbra run`: the whole pipeline for one world file. world file -> composer ->
// physics on its own thread -> snapshots at camera times -> renderer -> outputs.

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "penumbra/command/run_bridge.h"
#include "penumbra/world/world_config.h"

namespace penumbra {

class LiveControl;

/// options given on the command line that are not part of the world file.
struct RunOptions {
  std::string out_dir;                 ///< output folder; "" = world's output.dir
  std::optional<double> duration_sec;  ///< overrides the world's duration
  bool realtime = false;               ///< pace physics to wall-clock time (default: as fast as possible)
  bool progress = true;                ///< progress bar on a terminal / log lines otherwise
  /// --progress-interval: the least wall time between the pathtraced tier's sample-pass
  /// lines, s (ProgressOptions::pass_interval_sec; 0 = every pass)
  double progress_interval_sec = 1.0;
  std::vector<std::string> command_line;  ///< argv, recorded in run.json
  /// adversity preset spec (--adversity; world/adversity_preset.h), "" = the world's own
  std::string adversity;
  /// the output folder may hold the outputs of an earlier run, which are removed first
  /// (--force; output/output_folder.h). without it the folder must be empty or new.
  bool force = false;
  /// --record FILE.plog: write a run log (docs/run-log.md); overrides the world's `record:`
  /// file. relative to the current folder. "" = the world's `record:` (if any).
  std::string record_file;
  /// --record-sensors: the log also holds the cameras' images and the other sensors' outputs.
  bool record_sensors = false;
  /// --outputs: replaces the outputs of every camera (world-file and MJCF cameras).
  std::optional<CameraOutputs> outputs;
  /// a stop request (e.g. set by a SIGINT handler; nullptr = none): when it reads non-zero
  /// the run stops at the next physics step boundary, renders and writes what was captured
  /// up to there (a pathtraced frame stops between samples and is not written; also when the
  /// request comes after the last step), writes run.json with "interrupted": true and returns
  /// normally with RunSummary::interrupted set.
  const std::atomic<int>* stop_request = nullptr;
  /// middleware bridges attached to the run (command/run_bridge.h, e.g. --zmq's). with any,
  /// the run is live: its commands go through one CommandDispatcher, its steps through a
  /// RunControl (command/bridge_set.h), which also does the --realtime pacing.
  std::vector<RunBridgeFactory> bridges;
  /// with bridges: the run starts paused and advances only by `step` requests (--lockstep).
  bool lockstep = false;
  /// called once the run is set up, before its first step, on the caller's thread, with the
  /// run's live controls (live/live_control.h: adversity and effect changes, start/stop
  /// recording; thread-safe). the LiveControl lives until RunWorld returns: stop using it
  /// before then (e.g. in a sink's OnFinish). may be empty.
  std::function<void(LiveControl&)> on_live;
};

/// what a run produced.
struct RunSummary {
  std::string out_dir;
  double sim_time_sec = 0;  ///< sim time reached (time of the last completed step)
  int64_t physics_steps = 0;
  std::map<std::string, int64_t> frames_per_camera;
  double wall_time_sec = 0;
  double peak_rss_mib = 0;
  bool interrupted = false;  ///< stopped early by RunOptions::stop_request
  /// the run log written ("" = none), its size and its step records.
  std::string record_file;
  uint64_t record_bytes = 0;
  int64_t record_steps = 0;
};

/// the camera outputs named in a comma-separated list ("rgb,depth,segmentation"); valid names:
/// rgb, depth, segmentation, range, normals, instance_segmentation, semantic_segmentation.
/// @throws ConfigError (key "--outputs") for an empty list, an unknown name (the message
///         lists the valid ones) or a name given twice.
CameraOutputs ParseCameraOutputs(const std::string& list);

/// runs `world` and writes every output under the output folder (see README "Outputs").
/// physics runs on its own thread; rendering and writing happen on the caller's thread
/// and a writer pool. frames already written are kept if the run fails part-way.
///
/// failures: the first error of the run (physics divergence, or the first file that could
/// not be written, e.g. on a full disk) is the one rethrown, after the outputs written so far
/// are flushed and run.json (with an "error" entry) is written if possible; a later error
/// (e.g. run.json on the same full disk) is only logged. files are never left partial
/// (core/output_file.h).
/// @throws ConfigError for bad input (before anything runs), including an output folder that
///         is not empty without RunOptions::force (output/output_folder.h); PhysicsError if
///         the simulation diverges; Error for a write failure.
RunSummary RunWorld(const WorldConfig& world, const RunOptions& options);

}  // namespace penumbra
