#include "penumbra/replay/kinematic/replay_runner.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>

#include "penumbra/core/error.h"
#include "penumbra/live/live_effects.h"
#include "penumbra/output/manifest_sink.h"
#include "penumbra/output/output_folder.h"
#include "penumbra/output/run_manifest.h"
#include "penumbra/pipeline/sim_loop.h"
#include "penumbra/replay/log_source.h"
#include "penumbra/replay/recorded_world.h"
#include "penumbra/replay/world_override.h"
#include "penumbra/runlog/run_log_reader.h"
#include "penumbra/scene/sim_time.h"
#include "penumbra/session/effects_stage.h"
#include "penumbra/session/session.h"
#include "penumbra/sinks/run/run_outputs.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

void Warn(std::vector<std::string>* warnings, const std::string& w) {
  spdlog::warn("replay: {}", w);
  warnings->push_back(w);
}

ReplaySummary ReplayLocated(const ReplayOptions& options, const WorldConfig& recorded,
                            RunLogReader* reader, std::vector<std::string> warnings,
                            WorldOverride* applied, WorldConfig* world_out);

}  // namespace

int64_t FirstStepAtOrAfter(double time_sec, double timestep_sec) {
  if (!(time_sec > 0)) return 0;
  int64_t n = static_cast<int64_t>(std::floor(time_sec / timestep_sec));
  while (n > 0 && SimTimeOfStep(n - 1, timestep_sec) >= time_sec - 1e-9) --n;
  while (SimTimeOfStep(n, timestep_sec) < time_sec - 1e-9) ++n;
  return n;
}

ReplaySummary ReplayLog(const ReplayOptions& options) {
  if (options.out_dir.empty())
    throw ConfigError("", 0, "--out", "required; expected the replay's output folder");
  if (options.from_sec && options.to_sec && !(*options.from_sec < *options.to_sec))
    throw ConfigError("", 0, "--from",
                      fmt::format("{:.6g} s is not before --to {:.6g} s; expected from < to",
                                  *options.from_sec, *options.to_sec));

  RefuseOutputFolderHoldingLog(options.out_dir, options.log_path);
  RunLogReader reader = RunLogReader::Open(options.log_path, RunLogReadMode::kRecover);
  const RunLogHeader& header = reader.header();
  std::vector<std::string> warnings;
  if (reader.damage())
    Warn(&warnings,
         fmt::format("{}: {}; replaying up to there", options.log_path, *reader.damage()));
  for (const std::string& w : ChangedAssets(header))
    Warn(&warnings, w + "; the replay may differ from the recorded run");

  const WorldConfig recorded = RecordedWorld(header);
  WorldOverride applied;
  WorldConfig world;
  try {
    return ReplayLocated(options, recorded, &reader, std::move(warnings), &applied, &world);
  } catch (const ConfigError& e) {
    // errors the set-up stages raise still name the line of the override or the recorded world
    throw LocateReplayError(world.models.empty() ? recorded : world, applied, e);
  }
}

namespace {

ReplaySummary ReplayLocated(const ReplayOptions& options, const WorldConfig& recorded,
                            RunLogReader* reader, std::vector<std::string> warnings,
                            WorldOverride* applied, WorldConfig* world_out) {
  const auto t_start = Clock::now();
  const RunLogHeader& header = reader->header();

  // the recorded world with the replay's changes to what is seen
  WorldConfig& world = *world_out;
  world = recorded;
  if (!options.world_override.empty())
    world = ApplyWorldOverride(recorded, options.world_override, applied);
  std::string adversity = options.adversity;
  const bool override_adversity =
      std::find(applied->keys.begin(), applied->keys.end(), "adversity") != applied->keys.end();
  if (adversity.empty() && !override_adversity)
    adversity = ParseRecordedRunFlags(header.command_line).adversity;
  if (options.tier) world.render.tier = *options.tier;
  if (options.threads >= 0) world.render.threads = options.threads;
  if (options.backend) world.render.backend = *options.backend;
  if (options.outputs) {
    for (CameraConfig& c : world.cameras) c.outputs = *options.outputs;
    world.mjcf_cameras.outputs = *options.outputs;
    for (CameraConfig& c : world.mjcf_cameras.overrides) c.outputs = *options.outputs;
  }
  if (options.depth != ReplayDepth::kAsRecorded) {
    auto set_depth_model = [&](CameraConfig& c) {
      if (!c.outputs[ImageKind::kDepth]) return;
      DepthNoiseConfig& d = c.sensor.depth_noise;
      if (options.depth == ReplayDepth::kGroundTruth) {
        d = DepthNoiseConfig{};
      } else if (d.preset.empty()) {
        d.preset = options.default_depth_noise;
      }
    };
    for (CameraConfig& c : world.cameras) set_depth_model(c);
    for (CameraConfig& c : world.mjcf_cameras.overrides) set_depth_model(c);
  }
  world.output_dir = options.out_dir;
  world.render.seed = world.seed;
  world.ValidateOrThrow();

  const fs::path out = options.out_dir;
  std::error_code exists_ec;
  const bool out_existed = fs::exists(fs::symlink_status(out, exists_ec));
  // locked for the whole replay (output/output_lock.h)
  const OutputLock out_lock = PrepareOutputFolder(out, options.force, "--out");
  SetupRollback rollback(out, !out_existed);

  // the recorded world set up as `run` does, without controllers: nothing is simulated
  SessionOptions session_options;
  session_options.adversity = adversity;
  session_options.composed_xml_path = (out / "composed.xml").string();
  session_options.add_controllers = false;
  session_options.check_run_budget = true;
  session_options.reserve_live_npcs = ParseRecordedRunFlags(header.command_line).live;
  Session session(world, session_options);
  // agents the log does not hold move on their own while the robot moves as logged: a crowd
  // agent keeps clear of the logged robot as it would have in a run (effects/crowd_sim.h
  // "contact"); one that may touch it (scripted, contact: true, behaviour block) would pass
  // through it or be passed through where the run would have had a contact: refused
  for (const AgentConfig& a :
       TouchingAgentsWithout(session.effects().agents(), header.layout.mocap_body_names)) {
    const bool preset = a.name.rfind("adversity_", 0) == 0;
    const std::string why =
        a.robot_contact ? (preset ? "the preset's npcs.contact: true" : "contact: true")
        : a.behaviour == AgentBehaviour::kBlock && a.motion == AgentMotion::kCrowd
            ? "behaviour: block stands in the robot's way"
            : "motion: scripted follows its path whatever it touches";
    throw ConfigError(
        "", 0, preset ? (options.adversity.empty() ? "adversity" : "--adversity") : "agents",
        "agent '" + a.name + "' is not in the log and may touch the robot (" + why +
            "); a replay moves the robot as logged and cannot show the contact; expected "
            "agents that keep clear of the robot (motion: crowd, behaviour avoid or ignore, "
            "without contact), or a run recorded with this agent (penumbra run --record)");
  }
  // a stop (SIGINT / SIGTERM) also ends a pathtraced frame between samples
  if (Renderer* renderer = session.renderer()) renderer->set_stop_request(options.stop_request);
  Simulation& sim = session.sim();

  // the live changes of the run (live/live_effects.h), applied at their steps as the run
  // applied them; a replay under --adversity shows its own conditions instead
  LiveEffects live(session);
  int64_t live_changes = 0;
  for (const EventRecord& e : reader->Events()) {
    if (e.kind != "live") continue;
    ++live_changes;
    if (!options.adversity.empty()) continue;
    ScheduleRecordedLiveChange(e, options.log_path, &live);
  }
  if (live_changes > 0 && !options.adversity.empty())
    Warn(&warnings, fmt::format("--adversity replaces the recorded conditions: the log's {} live "
                                "change(s) are not applied",
                                live_changes));

  // the window
  const double dt = sim.timestep();
  const int64_t first_step = options.from_sec ? FirstStepAtOrAfter(*options.from_sec, dt) : 0;
  LogSource source(reader, &sim, LogSourceOptions{first_step});
  for (const std::string& name : source.state_map().dropped_mocap())
    Warn(&warnings, "the log's mocap body '" + name +
                        "' is not in the replay model (its agent was removed): not shown");
  const double end_time =
      options.to_sec ? *options.to_sec : SimTimeOfStep(reader->last_step(), header.timestep_sec);
  if (options.from_sec && source.time_sec() > end_time + 1e-9)
    throw ConfigError("", 0, "--from",
                      fmt::format("{:.6g} s is after the end of the log's window ({:.6g} s)",
                                  *options.from_sec, end_time));

  std::map<std::string, double> timings;
  timings["compose_sec"] = session.timings().compose_sec;
  timings["load_sec"] = session.timings().load_sec;
  timings["scene_build_sec"] = session.timings().scene_build_sec;

  // the sinks of `penumbra run` (sinks/run/run_outputs.h), fed by the log; the world's
  // `metrics:` on the kinematic quantities of the snapshots
  RunOutputsOptions outputs_options;
  outputs_options.end_time_sec = end_time;
  outputs_options.progress = options.progress;
  outputs_options.metrics_mode = MetricsMode::kKinematic;
  outputs_options.cameras = options.cameras;
  RunOutputs outputs(session, world, out, outputs_options);
  spdlog::info("replaying {} from {:.3f} s (step {}) to {:.3f} s, {} camera(s), out {}",
               options.log_path, source.time_sec(), source.step(), end_time,
               options.cameras.empty() ? session.scene().cameras.size() : options.cameras.size(),
               out.string());

  SimLoopOptions loop_options;
  loop_options.end_time_sec = end_time;
  loop_options.stop_request = options.stop_request;
  SimLoop loop(&source, loop_options);
  ReplaySummary summary;
  summary.first_step = source.step();
  ManifestSink manifest(out.string(), [&](const LoopFinish& f) {
    outputs.Finish(&timings);
    summary.out_dir = out.string();
    summary.last_step = f.step;
    summary.sim_time_sec = f.time_sec;
    // a stop that came after the last step still ended the pathtraced frames being rendered
    // (not written): the run is interrupted too
    summary.interrupted = f.reason == LoopEndReason::kStopRequested ||
                          (options.stop_request && options.stop_request->load() != 0);
    summary.frames_per_camera = outputs.cameras().FramesWritten();
    summary.wall_time_sec = SecondsSince(t_start);
    summary.warnings = warnings;
    for (const CameraConfig& c : world.cameras)
      if (c.outputs[ImageKind::kDepth]) summary.depth_models[c.name] = c.sensor.depth_noise.preset;
    for (const CameraConfig& c : world.mjcf_cameras.overrides)
      if (c.outputs[ImageKind::kDepth]) summary.depth_models[c.name] = c.sensor.depth_noise.preset;
    timings["total_sec"] = summary.wall_time_sec;
    RunManifest m = outputs.Describe(
        header.world_file.empty() ? header.model_file : header.world_file, options.command_line,
        f.time_sec, summary.interrupted, timings, PeakResidentMemoryMiB());
    ReplayManifest r;
    r.log = options.log_path;
    r.mode = "kinematic";
    r.first_step = summary.first_step;
    r.last_step = f.step;
    r.world_override = options.world_override;
    r.override_keys = applied->keys;
    r.adversity = options.adversity;
    if (options.tier)
      r.tier = *options.tier == RenderSettings::Tier::kPathtraced ? "pathtraced" : "realtime";
    r.cameras = options.cameras;
    r.outputs = options.outputs_text;
    r.warnings = warnings;
    m.replay = std::move(r);
    return m;
  });
  loop.AddSink(&live);  // first: a change applies before any sink sees its step
  outputs.AddTo(&loop);
  loop.AddSink(&manifest);
  rollback.Dismiss();
  const LoopFinish finish = loop.Run();
  if (finish.error) std::rethrow_exception(finish.error);
  return summary;
}

}  // namespace

}  // namespace penumbra
