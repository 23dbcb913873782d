#pragma once
// `penumbra replay FILE.plog --out DIR`: a recorded run rendered again with no physics. the
// recorded world (replay/recorded_world.h) is set up as `run` sets it up (session/session.h),
// without controllers, with the replay's changes to what is seen (--world override,
// replay/world_override.h; --adversity; --tier; --cameras; --outputs); a LogSource
// (replay/log_source.h) walks the log's states through the SimLoop into the SAME sinks as
// `penumbra run` (cameras, sensors, trajectory.csv, run.json), so the output folder has the
// layout of a run's (README "Outputs") plus a "replay" object in run.json.
//
// with the recorded conditions the frames are those of the run, byte for byte (same steps,
// same snapshots, same sinks); --from / --to render the frames of that window only, with the
// indices (file names) of the run's.
//
// agents: the log's own follow the log (agents that pushed the robot push it again). agents
// the replay adds (--adversity NPCs, an override's `agents:`) move on their own while the robot
// moves as logged: crowd agents read its logged pose and keep clear of it as in a run; one
// that may touch it (session/effects_stage.h AgentMayTouchRobot: scripted, contact, block)
// is refused before any frame, since the replay cannot show the contact.

#include <atomic>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "penumbra/render/render_settings.h"
#include "penumbra/scene/scene_description.h"

namespace penumbra {

/// the depth images of a replay's cameras with a depth output.
enum class ReplayDepth {
  kAsRecorded,   ///< each camera's world-file `depth_noise` (none = exact depth)
  kSensor,       ///< each camera's own `depth_noise`, else ReplayOptions::default_depth_noise
  kGroundTruth,  ///< exact z-depth for every camera (their `depth_noise` dropped)
};

/// what `penumbra replay` (kinematic) is asked for.
struct ReplayOptions {
  std::string log_path;  ///< the .plog
  std::string out_dir;   ///< output folder (required)
  /// the output folder may hold an earlier run's outputs, removed first (as run --force).
  bool force = false;
  /// adversity preset spec (world/adversity_preset.h); "" = as recorded.
  std::string adversity;
  /// world-file fragment replacing visual keys (replay/world_override.h); "" = none.
  std::string world_override;
  std::optional<RenderSettings::Tier> tier;  ///< --tier; nullopt = as recorded
  int threads = -1;                          ///< render threads, -1 = as recorded (0 = all cores)
  /// --backend: the render backend (render.backend); nullopt = as recorded.
  std::optional<RenderSettings::Backend> backend;
  /// --outputs: replaces the outputs of every camera; nullopt = as recorded. outputs_text is
  /// the list as given, for run.json.
  std::optional<CameraOutputs> outputs;
  std::string outputs_text;
  /// the depth model of the world-file cameras and MJCF camera overrides with a depth output
  /// (`penumbra export` of a run log asks for kSensor unless --depth ground-truth).
  ReplayDepth depth = ReplayDepth::kAsRecorded;
  /// the depth_noise preset kSensor gives a camera without its own: the benchmarks' camera
  /// model (campaign/benchmark_spec.h), sensors/depth_noise.h.
  std::string default_depth_noise = "realsense_d435";
  /// --cameras: the cameras to render, by name (empty = all).
  std::vector<std::string> cameras;
  /// the window of sim time replayed: from the first logged step at or after from_sec, to the
  /// first at or after to_sec (inclusive); nullopt = the log's first / last step.
  std::optional<double> from_sec, to_sec;
  bool progress = true;                   ///< progress bar / log lines
  std::vector<std::string> command_line;  ///< argv, for run.json
  /// a stop request (SIGINT): the replay stops at the next step, writes what it rendered and
  /// run.json ("interrupted": true); a pathtraced frame stops between samples and is not
  /// written (also when the request comes after the last step).
  const std::atomic<int>* stop_request = nullptr;
};

/// what a replay produced.
struct ReplaySummary {
  std::string out_dir;
  int64_t first_step = 0, last_step = 0;  ///< the logged steps replayed
  double sim_time_sec = 0;                ///< time of the last step replayed
  std::map<std::string, int64_t> frames_per_camera;
  double wall_time_sec = 0;
  bool interrupted = false;
  /// warnings (damaged log, changed assets, dropped mocap bodies), also logged and in run.json.
  std::vector<std::string> warnings;
  /// the depth_noise preset of each world-file camera and MJCF camera override with a depth
  /// output, by name ("" = exact depth), after ReplayOptions::depth.
  std::map<std::string, std::string> depth_models;
};

/// the first step whose time (SimTimeOfStep) is >= time_sec - 1e-9 s (the SimLoop's end rule).
int64_t FirstStepAtOrAfter(double time_sec, double timestep_sec);

/// replays the log as the file header describes. the log is read in recovery mode: a damaged
/// or cut log replays up to its last complete chunk, with a warning naming it.
/// @throws RunLogError for a file that is not a readable run log (bad magic, other format
///         version, truncated header); ConfigError for bad options (from >= to, a window
///         outside the log, unknown camera names, an override key that changes physics, an
///         output folder that is not empty without force) or a replay model that does not
///         match the log (a joint missing or changed), naming the file, line and key where one
///         applies; ConfigError("", 0, "--adversity" / "adversity" / "agents", ...) naming an
///         added agent that may touch the robot and why; Error for a write failure (after what was
///         rendered is flushed and run.json written, as in `run`).
ReplaySummary ReplayLog(const ReplayOptions& options);

}  // namespace penumbra
