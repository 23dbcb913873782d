#include "penumbra/app/runner.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <mutex>
#include <thread>

#include "penumbra/app/camera_stage.h"
#include "penumbra/app/sensor_stage.h"
#include "penumbra/core/bounded_queue.h"
#include "penumbra/core/error.h"
#include "penumbra/core/output_file.h"
#include "penumbra/output/async_frame_writer.h"
#include "penumbra/output/output_folder.h"
#include "penumbra/output/progress.h"
#include "penumbra/output/run_manifest.h"
#include "penumbra/physics/mujoco_version.h"
#include "penumbra/physics/simulation.h"
#include "penumbra/render/renderer.h"
#include "penumbra/render/renderer_factory.h"
#include "penumbra/sensors/sensor_schedule.h"
#include "penumbra/session/effects_stage.h"
#include "penumbra/session/scene_assembly.h"
#include "penumbra/session/session.h"

namespace penumbra {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// one unit of work from the physics thread: a snapshot and the cameras due at it.
struct RenderJob {
  WorldSnapshot snapshot;
  std::vector<int> cameras;
  std::vector<int64_t> frame_indices;
  std::vector<std::shared_ptr<const EffectsFrame>> effects;  // per camera (session/effects_stage.h)
  std::exception_ptr error;  // set on the last job if physics failed
};

// camera c fires its frame k at the first physics step whose time is >= k / rate_hz, on the
// step count (sensors/sensor_schedule.h), so frames never drift however the rate and timestep
// relate; a camera faster than physics renders once per step.
class CameraSchedule {
 public:
  CameraSchedule(const std::vector<CameraSpec>& cameras, double timestep_sec)
      : schedule_(timestep_sec) {
    for (const CameraSpec& c : cameras) {
      const int id = schedule_.Add(c.name, c.rate_hz);
      if (schedule_.exceeds_physics_rate(id))
        spdlog::warn(
            "camera '{}': rate_hz {:.6g} is faster than the physics rate ({:.6g} Hz); "
            "it renders one frame per physics step",
            c.name, c.rate_hz, schedule_.physics_rate_hz());
    }
  }

  void Due(int64_t step, std::vector<int>* cams, std::vector<int64_t>* frames) {
    due_.clear();
    schedule_.Due(step, &due_);
    for (const SensorFiring& f : due_) {
      cams->push_back(f.sensor);
      frames->push_back(f.index);
    }
  }

 private:
  SensorSchedule schedule_;
  std::vector<SensorFiring> due_;
};

std::string TrajectoryHeader(size_t nq) {
  std::string h = "step,time_sec";
  for (size_t i = 0; i < nq; ++i) fmt::format_to(std::back_inserter(h), ",qpos{}", i);
  return h + "\n";
}

std::string TrajectoryRow(const Simulation& sim) {
  const std::span<const double> q = sim.qpos();
  std::string row = fmt::format("{},{:.17g}", sim.step_count(), sim.time());
  for (double v : q) fmt::format_to(std::back_inserter(row), ",{:.17g}", v);
  row += '\n';
  return row;
}

// the first error of a run, from any thread (physics, render, writers)
class FirstError {
 public:
  // keeps `e` if it is the first; returns true if it was
  bool Record(std::exception_ptr e) {
    std::lock_guard<std::mutex> lock(mu_);
    if (first_) return false;
    first_ = e;
    return true;
  }
  std::exception_ptr get() const {
    std::lock_guard<std::mutex> lock(mu_);
    return first_;
  }

 private:
  mutable std::mutex mu_;
  std::exception_ptr first_;
};

std::string What(std::exception_ptr e) {
  try {
    std::rethrow_exception(e);
  } catch (const std::exception& x) {
    return x.what();
  } catch (...) {
    return "unknown error";
  }
}

RunSummary RunWorldUnlocated(const WorldConfig& world_in, const RunOptions& options);

// a run refused while it sets up (bad input found once the model is composed: an unknown body,
// a scene too large) leaves its output folder as it found it, empty or absent, so that the
// corrected command runs without --force. everything in the folder is this run's: it was empty
// or new when the run began (PrepareOutputFolder).
class SetupRollback {
 public:
  SetupRollback(std::filesystem::path out, bool created)
      : out_(std::move(out)), created_(created) {}
  SetupRollback(const SetupRollback&) = delete;
  SetupRollback& operator=(const SetupRollback&) = delete;
  ~SetupRollback() {
    if (done_) return;
    std::error_code ec;
    if (created_) {
      std::filesystem::remove_all(out_, ec);
      return;
    }
    std::vector<std::filesystem::path> entries;
    for (std::filesystem::directory_iterator it(out_, ec), end; !ec && it != end; it.increment(ec))
      entries.push_back(it->path());
    for (const std::filesystem::path& p : entries) std::filesystem::remove_all(p, ec);
  }
  /// the run has started: from here on what it wrote is kept
  void Dismiss() { done_ = true; }

 private:
  std::filesystem::path out_;
  bool created_ = false;
  bool done_ = false;
};

}  // namespace

CameraOutputs ParseCameraOutputs(const std::string& list) {
  std::string valid;
  for (std::string_view v : CameraOutputs::kNames)
    valid += (valid.empty() ? "" : ", ") + std::string(v);
  CameraOutputs o{false, false, false};
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

RunSummary RunWorldUnlocated(const WorldConfig& world_in, const RunOptions& options) {
  const auto t_start = Clock::now();
  WorldConfig world = world_in;
  if (options.duration_sec) world.duration_sec = *options.duration_sec;
  if (!options.out_dir.empty()) world.output_dir = options.out_dir;
  if (options.outputs) {
    for (CameraConfig& c : world.cameras) c.outputs = *options.outputs;
    world.mjcf_cameras.outputs = *options.outputs;
    for (CameraConfig& c : world.mjcf_cameras.overrides) c.outputs = *options.outputs;
  }
  world.render.seed = world.seed;
  world.ValidateOrThrow();

  namespace fs = std::filesystem;
  const fs::path out = world.output_dir;
  // empty or new, or (--force) holding only an earlier run's outputs (output/output_folder.h)
  std::error_code exists_ec;
  const bool out_existed = fs::exists(fs::symlink_status(out, exists_ec));
  PrepareOutputFolder(out, options.force, options.out_dir.empty() ? "output.dir" : "--out");
  SetupRollback rollback(out, !out_existed);

  std::map<std::string, double> timings;

  // compose, load, scene, effects and renderer, once (session/session.h); composed.xml is
  // kept next to the outputs
  SessionOptions session_options;
  session_options.adversity = options.adversity;
  session_options.composed_xml_path = (out / "composed.xml").string();
  session_options.check_run_budget = true;
  Session session(world, session_options);
  Simulation& sim = session.sim();
  const SceneDescription& scene = session.scene();
  EffectsStage& effects = session.effects();
  Renderer* const renderer = session.renderer();
  timings["compose_sec"] = session.timings().compose_sec;
  timings["load_sec"] = session.timings().load_sec;
  timings["scene_build_sec"] = session.timings().scene_build_sec;

  // outputs. the first error of any stage is the one reported (FirstError)
  FirstError first_error;
  AsyncFrameWriterOptions writer_options;
  writer_options.on_error = [&](std::exception_ptr e) { first_error.Record(e); };
  AsyncFrameWriter writer(out.string(), writer_options);
  for (const CameraSpec& cam : scene.cameras)
    writer.AddCamera(cam.name, cam.intrinsics, cam.outputs);
  CameraStage camera_stage(scene, world, renderer, out.string());  // app/camera_stage.h
  SensorStage sensor_stage(
      world, sim, scene, out.string(),  // app/sensor_stage.h
      [&](const WorldSnapshot& s, const Eigen::Vector3d& p) { return effects.Evaluate(s, p); });
  LineFile trajectory(out / "trajectory.csv");  // whole rows only (core/output_file.h)
  trajectory.Append(TrajectoryHeader(sim.qpos().size()));

  const double duration = world.duration_sec;
  ProgressOptions progress_options;
  progress_options.mode =
      options.progress ? ProgressOptions::Mode::kAuto : ProgressOptions::Mode::kOff;
  ProgressReporter progress(duration, progress_options);
  spdlog::info("running {} for {:.3f} s of sim time, {} camera(s), timestep {:.6g} s, out {}",
               world.file.empty() ? std::string("model") : world.file, duration,
               scene.cameras.size(), sim.timestep(), out.string());

  // physics on its own thread; it hands snapshots to the renderer through a bounded queue
  BoundedQueue<RenderJob> jobs(4);
  double physics_busy_sec = 0;
  double sim_time_reached = sim.time();
  bool interrupted = false;
  rollback.Dismiss();
  std::thread physics([&] {
    CameraSchedule schedule(scene.cameras, sim.timestep());
    ShutterSchedule shutters(scene, world);  // end-of-exposure snapshots (motion blur)
    const auto wall0 = Clock::now();
    try {
      for (;;) {
        RenderJob job;
        schedule.Due(sim.step_count(), &job.cameras, &job.frame_indices);
        const bool sensors_due = sensor_stage.Due(sim.step_count());  // same snapshot as cameras
        const bool shutter_due = shutters.Due(sim.time());
        if (sensors_due && !shutter_due && job.cameras.empty())
          sensor_stage.Process(sim.Snapshot());
        if (shutter_due || !job.cameras.empty()) {
          // cameras and effects read poses only: the full forward pass (sensordata, body
          // velocities, contacts) only when the sensors read this snapshot too
          job.snapshot = sim.Snapshot(sensors_due ? Simulation::SnapshotContent::kFull
                                                  : Simulation::SnapshotContent::kPoses);
          if (sensors_due) sensor_stage.Process(job.snapshot);
          shutters.Add(job.snapshot.time_sec, job.cameras);
          for (int c : job.cameras)
            job.effects.push_back(effects.Evaluate(
                job.snapshot, CameraPoseInWorld(scene.cameras[c], job.snapshot).translation()));
          if (!jobs.Push(std::move(job))) return;
        }
        if (sim.time() >= duration - 1e-9) break;
        // a stop request (SIGINT/SIGTERM) ends the run at this step boundary
        if (options.stop_request && options.stop_request->load() != 0) {
          interrupted = true;
          break;
        }
        if (options.realtime) {
          std::this_thread::sleep_until(wall0 + std::chrono::duration_cast<Clock::duration>(
                                                    std::chrono::duration<double>(sim.time())));
        }
        const auto ts = Clock::now();
        sim.Step();
        physics_busy_sec += SecondsSince(ts);
        sim_time_reached = sim.time();
        trajectory.Append(TrajectoryRow(sim));
        for (const std::string& w : sim.TakeWarnings()) spdlog::warn("physics: {}", w);
      }
    } catch (...) {
      first_error.Record(std::current_exception());
      RenderJob last;
      last.error = std::current_exception();
      jobs.Push(std::move(last));
    }
    jobs.Close();
  });

  // render and write on this thread, in arrival order (deterministic)
  RunSummary summary;
  double render_sec = 0;
  int64_t total_frames = 0;
  const CameraStage::Submit submit = [&](CameraFrame&& cf) {
    ++summary.frames_per_camera[cf.camera];
    ++total_frames;
    writer.Submit(std::move(cf));
  };
  bool failed = false;
  try {
    while (std::optional<RenderJob> job = jobs.Pop()) {
      if (job->error) {
        failed = true;
        break;
      }
      // per-camera effects (session/effects_stage.h) ride along with each capture
      camera_stage.OnSnapshot(job->snapshot, job->cameras, job->frame_indices, job->effects,
                              submit);
      progress.Update(job->snapshot.time_sec, total_frames);
    }
    if (!failed) camera_stage.Finish(submit);
  } catch (...) {
    first_error.Record(std::current_exception());
  }
  jobs.Close();
  physics.join();
  progress.Finish();
  render_sec = camera_stage.render_sec();

  // drain every writer; each reports its own error, the run reports the first one
  auto drain = [&](auto&& f) {
    try {
      f();
    } catch (...) {
      first_error.Record(std::current_exception());
    }
  };
  drain([&] { sensor_stage.Finish(); });
  drain([&] { writer.Flush(); });
  drain([&] { trajectory.Close(); });
  for (const auto& [kind, sec] : sensor_stage.busy_sec()) timings["sensors_" + kind + "_sec"] = sec;
  // frames.csv rows actually written (a frame whose files failed has none)
  summary.frames_per_camera = writer.FramesWritten();

  summary.out_dir = out.string();
  summary.sim_time_sec = sim_time_reached;
  summary.physics_steps = sim.step_count();
  summary.interrupted = interrupted;
  summary.wall_time_sec = SecondsSince(t_start);
  summary.peak_rss_mib = PeakResidentMemoryMiB();
  timings["physics_sec"] = physics_busy_sec;
  timings["render_sec"] = render_sec;
  timings["total_sec"] = summary.wall_time_sec;

  const std::exception_ptr failure = first_error.get();
  RunManifest manifest;
  manifest.world_file =
      world.file.empty() && !world.models.empty() ? world.models.front().file : world.file;
  manifest.seed = world.seed;
  manifest.penumbra_version = PENUMBRA_VERSION;
  manifest.mujoco_version = MujocoVersion();
  manifest.embree_version = RendererVersion(world.render.backend);
  manifest.timings_sec = timings;
  manifest.peak_resident_memory_mib = summary.peak_rss_mib;
  manifest.frames_per_camera = summary.frames_per_camera;
  manifest.sim_duration_sec = summary.sim_time_sec;
  manifest.interrupted = interrupted;
  if (failure) manifest.error = What(failure);
  manifest.command_line = options.command_line;
  manifest.adversity = effects.PresetLabel();
  manifest.effects = effects.EffectLabels();
  manifest.agents = effects.AgentLabels();
  try {
    WriteRunManifest(out.string(), manifest);
  } catch (...) {
    // on a full disk run.json fails too; the error that came first is the one reported
    if (!first_error.Record(std::current_exception()))
      spdlog::warn("after the first error, also: {}", What(std::current_exception()));
  }

  if (const std::exception_ptr e = first_error.get()) std::rethrow_exception(e);
  return summary;
}

}  // namespace

}  // namespace penumbra
