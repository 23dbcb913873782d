#include "penumbra/run/runner.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <utility>

#include "penumbra/command/bridge_set.h"
#include "penumbra/core/build_info.h"
#include "penumbra/core/error.h"
#include "penumbra/core/output_file.h"
#include "penumbra/core/output_path_policy.h"
#include "penumbra/live/live_control.h"
#include "penumbra/live/run_log_header.h"
#include "penumbra/output/manifest_sink.h"
#include "penumbra/output/output_folder.h"
#include "penumbra/output/output_lock.h"
#include "penumbra/output/png_io.h"
#include "penumbra/output/recorder_sink.h"
#include "penumbra/output/run_manifest.h"
#include "penumbra/physics/physics_source.h"
#include "penumbra/physics/simulation.h"
#include "penumbra/pipeline/sim_loop.h"
#include "penumbra/session/npc_map_json.h"
#include "penumbra/session/scene_assembly.h"
#include "penumbra/session/session.h"
#include "penumbra/sinks/run/run_outputs.h"

namespace penumbra {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

RunSummary RunWorldUnlocated(const WorldConfig& world_in, const RunOptions& options);

}  // namespace

CameraOutputs ParseCameraOutputs(const std::string& list) {
  std::string valid;
  for (const ImageKindInfo& k : kImageKinds)
    valid += (valid.empty() ? "" : ", ") + std::string(k.name);
  CameraOutputs o = CameraOutputs::None();
  size_t start = 0, count = 0;
  while (start <= list.size()) {
    size_t end = list.find(',', start);
    if (end == std::string::npos) end = list.size();
    const std::string name = list.substr(start, end - start);
    start = end + 1;
    bool* flag = o.Flag(name);
    if (!flag)
      throw ConfigError(
          "", 0, "--outputs",
          "unknown output '" + name + "'; expected a comma-separated list of: " + valid);
    if (*flag) throw ConfigError("", 0, "--outputs", "'" + name + "' is listed twice");
    *flag = true;
    ++count;
  }
  if (count == 0) throw ConfigError("", 0, "--outputs", "empty list; expected some of: " + valid);
  return o;
}

RunSummary RunWorld(const WorldConfig& world, const RunOptions& options) {
  // errors the stages raise after loading still name the world file's line
  try {
    return RunWorldUnlocated(world, options);
  } catch (const ConfigError& e) {
    throw LocateInWorld(world, e);
  }
}

namespace {

// the world with the command line's overrides applied, validated
WorldConfig WithRunOptions(const WorldConfig& world_in, const RunOptions& options) {
  WorldConfig world = world_in;
  if (options.duration_sec) world.duration_sec = *options.duration_sec;
  if (!options.out_dir.empty()) world.output_dir = options.out_dir;
  if (options.outputs) {
    for (CameraConfig& c : world.cameras) c.outputs = *options.outputs;
    world.mjcf_cameras.outputs = *options.outputs;
    for (CameraConfig& c : world.mjcf_cameras.overrides) c.outputs = *options.outputs;
  }
  if (!options.record_file.empty()) world.record.file = options.record_file;
  if (options.record_sensors) world.record.sensors = true;
  world.render.seed = world.seed;
  try {
    world.ValidateOrThrow();
  } catch (const ConfigError& e) {
    // a bad --record / --record-sensors is the command line's, not the world file's
    if (e.key().rfind("record.", 0) == 0 && !options.record_file.empty())
      throw ConfigError("", 0, "--record", e.problem());
    if (e.key() == "record.sensors" && options.record_sensors)
      throw ConfigError("", 0, "--record-sensors",
                        "needs --record FILE.plog (or world-file record.file)");
    throw;
  }
  return world;
}

// a run log this run created, removed should the run fail before its first step
class NewLogRollback {
 public:
  explicit NewLogRollback(std::string path) : path_(std::move(path)) {}
  NewLogRollback(const NewLogRollback&) = delete;
  NewLogRollback& operator=(const NewLogRollback&) = delete;
  ~NewLogRollback() {
    if (!path_.empty()) ::unlink(path_.c_str());
  }
  void Dismiss() { path_.clear(); }

 private:
  std::string path_;
};

std::string JoinArgs(const std::vector<std::string>& args) {
  std::string s;
  for (const std::string& a : args) s += (s.empty() ? "" : " ") + a;
  return s;
}

RunSummary RunWorldUnlocated(const WorldConfig& world_in, const RunOptions& options) {
  const auto t_start = Clock::now();
  const WorldConfig world = WithRunOptions(world_in, options);

  namespace fs = std::filesystem;
  const fs::path out = world.output_dir;
  // empty or new, or (--force) holding only an earlier run's outputs (output/output_folder.h)
  std::error_code exists_ec;
  const bool out_existed = fs::exists(fs::symlink_status(out, exists_ec));
  // locked for the whole run: a second run into it fails here naming this one's PID
  const OutputLock out_lock =
      PrepareOutputFolder(out, options.force, options.out_dir.empty() ? "output.dir" : "--out");
  SetupRollback rollback(out, !out_existed);
  // the run log, opened now so that a second run into the same log fails at start (its header
  // is written once the session is set up): --record is the user's, relative to the current
  // folder, locked, replacing an existing log only with --force; the world file's record.file
  // is a new file inside the output folder (core/output_path_policy.h: no absolute path, "..",
  // symbolic link or existing file)
  UniqueFd record_fd;
  std::string record_path, record_created;
  if (!options.record_file.empty()) {
    LockedRunLogFile f = OpenRunLogFile(options.record_file, options.force, "--record");
    record_path = fs::path(f.path).lexically_normal().string();
    record_fd = std::move(f.fd);
    if (f.created) record_created = f.path;
  } else if (!world.record.file.empty()) {
    try {
      NewOutputFile f = OpenNewFileInside(out, world.record.file, ".plog");
      record_fd = std::move(f.fd);
      record_path = (out / f.relative).lexically_normal().string();
    } catch (const OutputPathError& e) {
      throw ConfigError("", 0, "record.file",
                        "'" + SanitizeForMessage(world.record.file, 300) + "' " + e.rule() +
                            "; expected a new file ending in .plog inside the output folder");
    }
  }
  NewLogRollback log_rollback(record_created);

  std::map<std::string, double> timings;

  // compose, load, scene, effects and renderer, once (session/session.h); composed.xml is
  // kept next to the outputs
  SessionOptions session_options;
  session_options.adversity = options.adversity;
  session_options.composed_xml_path = (out / "composed.xml").string();
  session_options.check_run_budget = true;
  session_options.reserve_live_npcs = !options.bridges.empty();
  // a SIGINT / SIGTERM during the set-up ends it (SetupInterrupted)
  session_options.stop_request = options.stop_request;
  Session session(world, session_options);
  // a crowd's walkable map goes with the run (npc_map.png, docs/npcs.md)
  if (const std::shared_ptr<const NpcMap> npc_map = session.effects().npc_map()) {
    std::vector<Eigen::Vector2d> robots, agents;
    for (const ModelConfig& m : world.models)
      if (m.is_robot) robots.push_back(m.pose.xyz.head<2>());
    for (const CrowdAgentState& a : session.effects().crowd()->crowd().states())
      agents.push_back(a.position_W);
    WritePngRgb8((out / "npc_map.png").string(),
                 npc_map->Draw(session.effects().sites(), robots, agents));
    // the same map as data (what the viewer's scene view draws)
    const std::string json_path = (out / "npc_map.json").string();
    std::ofstream json_file(json_path);
    json_file << NpcMapJson(session) << "\n";
    if (!json_file) throw Error("cannot write " + json_path);
  }
  // a stop (SIGINT / SIGTERM) also ends a pathtraced frame between samples
  if (Renderer* renderer = session.renderer()) renderer->set_stop_request(options.stop_request);
  Simulation& sim = session.sim();
  const SceneDescription& scene = session.scene();
  timings["compose_sec"] = session.timings().compose_sec;
  timings["load_sec"] = session.timings().load_sec;
  timings["scene_build_sec"] = session.timings().scene_build_sec;

  // the pipeline (docs/architecture.md): physics -> SimLoop -> sinks. every output file is
  // written by a sink on its own thread; the first error of any of them is the one reported.
  const double duration = world.duration_sec;
  RunOutputsOptions outputs_options;
  outputs_options.end_time_sec = duration;
  outputs_options.progress = options.progress;
  outputs_options.progress_pass_interval_sec = options.progress_interval_sec;
  outputs_options.metrics_mode = MetricsMode::kDynamics;
  // a live run paced to the wall clock (bridges or viewer with --realtime): one snapshot
  // waiting for the renderer, not four, so that a teleop command shows in the next frames
  if (options.realtime && !options.bridges.empty()) outputs_options.render_queue = 1;
  // --record-sensors: every image file the cameras write also goes into the run log (set
  // once the log is open, before the loop starts)
  RunLogWriter* sensor_log = nullptr;
  // the live controls (live/live_control.h); their recordings take sensor records too
  LiveControl live(session, JoinArgs(options.command_line), out);
  outputs_options.on_image = [&sensor_log, &live](const CameraFrame& f, const std::string& kind,
                                                  const std::vector<uint8_t>& png) {
    if (!sensor_log && !live.recorder().wants_sensor_records()) return;
    const SensorRecord r{f.step, f.time_sec, f.camera, kind + ".png",
                         std::string(png.begin(), png.end())};
    if (sensor_log) sensor_log->RecordSensor(r);
    live.recorder().RecordSensor(r);
  };
  RunOutputs outputs(session, world, out, outputs_options);
  spdlog::info("running {} for {:.3f} s of sim time, {} camera(s), timestep {:.6g} s, out {}",
               world.file.empty() ? std::string("model") : world.file, duration,
               scene.cameras.size(), sim.timestep(), out.string());

  PhysicsSourceOptions physics_options;
  physics_options.realtime = options.realtime;
  SimLoopOptions loop_options;
  loop_options.end_time_sec = duration;
  loop_options.stop_request = options.stop_request;
  // middleware bridges (--zmq, ...): commands and steps through one RunControl
  std::unique_ptr<BridgeSet> bridges;
  if (!options.bridges.empty()) {
    bridges =
        std::make_unique<BridgeSet>(session, world, outputs,
                                    BridgeSetOptions{options.lockstep, options.realtime ? 1.0 : 0.0,
                                                     options.stop_request, &live},
                                    options.bridges);
    bridges->Configure(&physics_options, &loop_options);
  }
  PhysicsSource physics(&sim, physics_options);
  SimLoop loop(&physics, loop_options);
  RunSummary summary;
  // the run log (--record): every step's state from the loop thread, closed (complete) at the
  // end of the run, also after Ctrl-C or an error; the file was opened (and locked) at the start,
  // its header is written now that the session is set up (a setup error removed a new file)
  std::unique_ptr<RecorderSink> recorder;
  if (record_fd.get() >= 0) {
    RunLogHeader header =
        MakeRunLogHeader(session, PENUMBRA_VERSION, JoinArgs(options.command_line));
    header.has_sensor_records = world.record.sensors;
    recorder = std::make_unique<RecorderSink>(std::move(record_fd), record_path, header);
    if (world.record.sensors) sensor_log = &recorder->writer();
    live.RecordChangesTo(&recorder->writer());
    // the crowd's decisions (goals, plans, pauses) as "npc" events (docs/npcs.md)
    RunLogWriter* npc_log = &recorder->writer();
    const double timestep = sim.timestep();
    session.effects().set_crowd_decision_sink(
        [npc_log, timestep](double t, const std::string& json) {
          npc_log->RecordEvent(std::llround(t / timestep), t, "npc", json);
        });
    spdlog::info("recording the run to {}", record_path);
  }
  outputs.sensors().set_on_output([&sensor_log, &live](const std::string& sensor,
                                                       const std::string& kind, int64_t step,
                                                       double time_sec, std::string bytes) {
    if (!sensor_log && !live.recorder().wants_sensor_records()) return;
    const SensorRecord r{step, time_sec, sensor, kind, std::move(bytes)};
    if (sensor_log) sensor_log->RecordSensor(r);
    live.recorder().RecordSensor(r);
  });
  ManifestSink manifest(out.string(), [&](const LoopFinish& f) {
    outputs.Finish(&timings);
    summary.out_dir = out.string();
    summary.sim_time_sec = f.time_sec;
    summary.physics_steps = sim.step_count();
    // a stop that came after the last step still ended the pathtraced frames being rendered
    // (not written): the run is interrupted too
    summary.interrupted = f.reason == LoopEndReason::kStopRequested ||
                          (options.stop_request && options.stop_request->load() != 0);
    summary.frames_per_camera = outputs.cameras().FramesWritten();  // frames.csv rows written
    summary.wall_time_sec = SecondsSince(t_start);
    summary.peak_rss_mib = PeakResidentMemoryMiB();
    timings["physics_sec"] = physics.busy_sec();
    timings["total_sec"] = summary.wall_time_sec;
    RunManifest m = outputs.Describe(
        world.file.empty() && !world.models.empty() ? world.models.front().file : world.file,
        options.command_line, summary.sim_time_sec, summary.interrupted, timings,
        summary.peak_rss_mib);
    if (recorder) {
      const RunLogWriterStats st = recorder->stats();
      summary.record_file = record_path;
      summary.record_bytes = st.file_bytes;
      summary.record_steps = st.steps;
      m.record_file = summary.record_file;
      m.record_bytes = summary.record_bytes;
      m.record_steps = summary.record_steps;
      m.record_first_step = st.first_step;
      m.record_last_step = st.last_step;
      m.record_events = st.events;
      m.record_sensor_records = st.sensor_records;
    }
    return m;
  });
  // the sinks' stages order them (pipeline/sink.h SinkStage): live changes, outputs, recorders,
  // the run control, the bridges, run.json
  live.AddTo(&loop);
  outputs.AddTo(&loop);
  if (recorder) loop.AddSink(recorder.get());
  if (bridges) bridges->AddTo(&loop);
  loop.AddSink(&manifest);
  rollback.Dismiss();
  log_rollback.Dismiss();
  if (options.on_live) options.on_live(live);
  const LoopFinish finish = loop.Run();
  if (finish.error) std::rethrow_exception(finish.error);
  return summary;
}

}  // namespace

}  // namespace penumbra
