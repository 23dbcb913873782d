#include "penumbra/replay/replay_runner.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <initializer_list>

#include "penumbra/core/error.h"
#include "penumbra/output/manifest_sink.h"
#include "penumbra/output/output_folder.h"
#include "penumbra/output/progress.h"
#include "penumbra/output/run_manifest.h"
#include "penumbra/output/trajectory_sink.h"
#include "penumbra/physics/mujoco_version.h"
#include "penumbra/pipeline/sim_loop.h"
#include "penumbra/render/renderer_factory.h"
#include "penumbra/replay/log_source.h"
#include "penumbra/replay/recorded_world.h"
#include "penumbra/replay/world_override.h"
#include "penumbra/runlog/run_log_reader.h"
#include "penumbra/scene/sim_time.h"
#include "penumbra/session/camera_sink.h"
#include "penumbra/session/sensor_sink.h"
#include "penumbra/session/session.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// a replay refused while it sets up leaves its output folder as it found it (empty or absent),
// as `penumbra run` does
class SetupRollback {
 public:
  SetupRollback(fs::path out, bool created) : out_(std::move(out)), created_(created) {}
  SetupRollback(const SetupRollback&) = delete;
  SetupRollback& operator=(const SetupRollback&) = delete;
  ~SetupRollback() {
    if (done_) return;
    std::error_code ec;
    if (created_) {
      fs::remove_all(out_, ec);
      return;
    }
    std::vector<fs::path> entries;
    for (fs::directory_iterator it(out_, ec), end; !ec && it != end; it.increment(ec))
      entries.push_back(it->path());
    for (const fs::path& p : entries) fs::remove_all(p, ec);
  }
  void Dismiss() { done_ = true; }

 private:
  fs::path out_;
  bool created_ = false;
  bool done_ = false;
};

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

  {
    // --force empties the output folder: never the one that holds the log being replayed
    std::error_code ec;
    const fs::path log = fs::weakly_canonical(options.log_path, ec);
    const fs::path out = fs::weakly_canonical(options.out_dir, ec);
    const std::string rel = log.lexically_relative(out).string();
    if (!ec && !rel.empty() && rel.rfind("..", 0) != 0)
      throw ConfigError("", 0, "--out",
                        "'" + options.out_dir + "' holds the log being replayed (" +
                            options.log_path + "); expected another output folder");
  }
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
  if (options.outputs) {
    for (CameraConfig& c : world.cameras) c.outputs = *options.outputs;
    world.mjcf_cameras.outputs = *options.outputs;
    for (CameraConfig& c : world.mjcf_cameras.overrides) c.outputs = *options.outputs;
  }
  world.output_dir = options.out_dir;
  world.render.seed = world.seed;
  world.ValidateOrThrow();

  const fs::path out = options.out_dir;
  std::error_code exists_ec;
  const bool out_existed = fs::exists(fs::symlink_status(out, exists_ec));
  PrepareOutputFolder(out, options.force, "--out");
  SetupRollback rollback(out, !out_existed);

  // the recorded world set up as `run` does, without controllers: nothing is simulated
  SessionOptions session_options;
  session_options.adversity = adversity;
  session_options.composed_xml_path = (out / "composed.xml").string();
  session_options.add_controllers = false;
  session_options.check_run_budget = true;
  Session session(world, session_options);
  Simulation& sim = session.sim();
  EffectsStage& effects = session.effects();

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

  // the sinks of `penumbra run` (app/runner.cc), fed by the log
  const ViewerEffects viewer_effects = [&](const WorldSnapshot& s, const Eigen::Vector3d& p_W) {
    return effects.Evaluate(s, p_W);
  };
  std::optional<ProgressReporter> progress;
  CameraSinkOptions camera_options;
  camera_options.on_rendered = [&](double t, int64_t frames) { progress->Update(t, frames); };
  camera_options.cameras = options.cameras;
  CameraSink cameras(session.scene(), world, dt, session.renderer(), out.string(), viewer_effects,
                     camera_options);
  SensorSink sensors(world, sim, session.scene(), out.string(), viewer_effects);
  TrajectorySink trajectory(out / "trajectory.csv", sim.qpos().size());
  // sinks that also run in a replay are added here, before the manifest (e.g. the world's
  // `metrics:` sink, on the kinematic quantities of the snapshots)
  ProgressOptions progress_options;
  progress_options.mode =
      options.progress ? ProgressOptions::Mode::kAuto : ProgressOptions::Mode::kOff;
  progress.emplace(end_time, progress_options);
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
    progress->Finish();
    for (const auto& [kind, sec] : sensors.busy_sec()) timings["sensors_" + kind + "_sec"] = sec;
    summary.out_dir = out.string();
    summary.last_step = f.step;
    summary.sim_time_sec = f.time_sec;
    summary.interrupted = f.reason == LoopEndReason::kStopRequested;
    summary.frames_per_camera = cameras.FramesWritten();
    summary.wall_time_sec = SecondsSince(t_start);
    summary.warnings = warnings;
    timings["render_sec"] = cameras.render_sec();
    timings["total_sec"] = summary.wall_time_sec;
    RunManifest m;
    m.world_file = header.world_file.empty() ? header.model_file : header.world_file;
    m.seed = world.seed;
    m.penumbra_version = PENUMBRA_VERSION;
    m.mujoco_version = MujocoVersion();
    m.embree_version = RendererVersion(world.render.backend);
    m.timings_sec = timings;
    m.peak_resident_memory_mib = PeakResidentMemoryMiB();
    m.frames_per_camera = summary.frames_per_camera;
    m.sim_duration_sec = f.time_sec;
    m.interrupted = summary.interrupted;
    m.command_line = options.command_line;
    m.adversity = effects.PresetLabel();
    m.effects = effects.EffectLabels();
    m.agents = effects.AgentLabels();
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
  for (Sink* sink : std::initializer_list<Sink*>{&sensors, &cameras, &trajectory, &manifest})
    loop.AddSink(sink);
  rollback.Dismiss();
  const LoopFinish finish = loop.Run();
  if (finish.error) std::rethrow_exception(finish.error);
  return summary;
}

}  // namespace

}  // namespace penumbra
