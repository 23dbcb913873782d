#include "penumbra/replay/resimulate.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>

#include "penumbra/core/build_info.h"
#include "penumbra/core/error.h"
#include "penumbra/live/live_effects.h"
#include "penumbra/live/run_log_header.h"
#include "penumbra/metrics/metrics_sink.h"
#include "penumbra/output/manifest_sink.h"
#include "penumbra/output/output_folder.h"
#include "penumbra/output/run_manifest.h"
#include "penumbra/physics/mujoco_version.h"
#include "penumbra/physics/physics_source.h"
#include "penumbra/physics/simulation.h"
#include "penumbra/pipeline/sim_loop.h"
#include "penumbra/replay/log_source.h"
#include "penumbra/replay/recorded_world.h"
#include "penumbra/replay/state_map.h"
#include "penumbra/runlog/run_log_reader.h"
#include "penumbra/session/session.h"

namespace penumbra {
namespace {

// what entry i of a state field belongs to, from the log's layout
std::string EntryOwner(const RunLogLayout& l, StateField field, int64_t i) {
  const auto joint = [&](bool qpos) -> std::string {
    for (const RunLogJoint& j : l.joints) {
      const int adr = qpos ? j.qpos_adr : j.qvel_adr;
      const int width = qpos ? j.qpos_width : j.qvel_width;
      if (i >= adr && i < adr + width)
        return "joint '" + j.name + "'" + (width > 1 ? fmt::format(" entry {}", i - adr) : "");
    }
    return "";
  };
  const auto named = [](const std::vector<std::string>& names, int64_t k, const char* kind,
                        int64_t width, const char* const* parts) -> std::string {
    if (k < 0 || k / width >= static_cast<int64_t>(names.size())) return "";
    return std::string(kind) + " '" + names[k / width] + "'" +
           (parts ? std::string(" ") + parts[k % width] : "");
  };
  static const char* const kXyz[] = {"x", "y", "z"};
  static const char* const kWxyz[] = {"w", "x", "y", "z"};
  static const char* const kWrench[] = {"torque x", "torque y", "torque z",
                                        "force x",  "force y",  "force z"};
  // by what the field's entries index (its dimension). act: the layout does not say which
  // actuator an activation belongs to (MuJoCo 4's actuator_actadr), so it is not named
  if (field == StateField::kAct) return "";
  switch (StateFieldOf(field).dim) {
    case StateDim::kNq:
      return joint(true);
    case StateDim::kNv:
      return joint(false);
    case StateDim::kNu:
      return named(l.actuator_names, i, "actuator", 1, nullptr);
    case StateDim::kNbody:
      return named(l.body_names, i, "body", 6, kWrench);
    case StateDim::kNmocap:
      return field == StateField::kMocapPos ? named(l.mocap_body_names, i, "mocap body", 3, kXyz)
                                            : named(l.mocap_body_names, i, "mocap body", 4, kWxyz);
    case StateDim::kNumControllers:
      return named(l.controller_names, i, "controller", 1, nullptr);
    case StateDim::kNeq:
      return fmt::format("equality constraint {}", i);
    case StateDim::kNa:
    case StateDim::kNuserdata:
    case StateDim::kNhistory:
    case StateDim::kNpluginstate:
    case StateDim::kNplastic:
      return "";
  }
  return "";
}

bool SameEntry(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }
bool SameEntry(int64_t a, int64_t b) { return a == b; }

// the first difference between the logged record and the simulated state, if any, in the
// fields a log of `format_version` holds (RunLogStateShapeOf: a format 1 log has no history,
// eq_active, plugin_state or plastic)
std::optional<Divergence> Compare(const StepRecord& r, const SimState& s, const RunLogLayout& l,
                                  bool check_schedule, uint32_t format_version) {
  const int recorded_fields = RunLogStateShapeOf(format_version).fields;
  Divergence d;
  d.step = r.step;
  d.time_sec = r.time_sec;
  if (r.step != s.step) {
    d.field = "step";
    d.logged = static_cast<double>(r.step);
    d.simulated = static_cast<double>(s.step);
    return d;
  }
  if (!SameEntry(r.time_sec, s.time_sec)) {
    d.field = "time_sec";
    d.logged = r.time_sec;
    d.simulated = s.time_sec;
    return d;
  }
  bool found = false;
  ForEachStateField(
      [&](const StateFieldInfo& f, const auto& a, const auto& b) {
        if (found || static_cast<int>(f.field) >= recorded_fields ||
            (f.field == StateField::kControllerNextUpdate && !check_schedule))
          return;
        if (a.size() != b.size()) {
          d.field = "size of " + std::string(f.name);
          d.logged = static_cast<double>(a.size());
          d.simulated = static_cast<double>(b.size());
          found = true;
          return;
        }
        for (size_t i = 0; i < a.size(); ++i) {
          if (SameEntry(a[i], b[i])) continue;
          d.field = std::string(f.name);
          d.index = static_cast<int64_t>(i);
          d.what = EntryOwner(l, f.field, d.index);
          d.logged = static_cast<double>(a[i]);
          d.simulated = static_cast<double>(b[i]);
          found = true;
          return;
        }
      },
      r, s);
  if (found) return d;
  return std::nullopt;
}

// the log read in step with the simulation: before each step the record of that step is read
// (its ctrl applied in kCtrl mode; PhysicsSourceOptions::before_step), and as a sink every
// step's snapshot is compared with it. the first divergence, or the log's end, ends the source.
class LogCheck : public Sink {
 public:
  LogCheck(RunLogReader* reader, const RunLogLayout& layout, bool controllers, std::string log_path,
           StepRecord first, ResimulateReport* report)
      : reader_(reader),
        layout_(layout),
        format_version_(reader->header().format_version),
        controllers_(controllers),
        log_path_(std::move(log_path)),
        record_(std::move(first)),
        report_(report) {}

  bool BeforeStep(Simulation& sim) {
    if (report_->divergence || !reader_->NextStep(&record_)) return false;
    if (record_.step != sim.step_count() + 1)
      throw ConfigError(log_path_, 0, "",
                        fmt::format("the log skips from step {} to step {}; expected every step",
                                    sim.step_count(), record_.step));
    if (!controllers_) {
      // the ctrl the controllers wrote during this step, as logged after it
      std::span<double> ctrl = sim.ctrl();
      if (record_.ctrl.size() != ctrl.size())
        throw ConfigError(log_path_, 0, "", "logged ctrl has another size than the model's");
      std::copy(record_.ctrl.begin(), record_.ctrl.end(), ctrl.begin());
    }
    return true;
  }

  SnapshotContent Wants(int64_t step, double) override {
    return step > last_checked_ ? SnapshotContent::kState : SnapshotContent::kNone;
  }
  void OnSnapshot(const std::shared_ptr<const WorldSnapshot>& snapshot) override {
    if (snapshot->step <= last_checked_) return;
    last_checked_ = snapshot->step;
    report_->divergence = Compare(record_, *snapshot, layout_, controllers_, format_version_);
    ++report_->steps_checked;
    report_->last_step = record_.step;
  }

 private:
  RunLogReader* reader_;
  const RunLogLayout& layout_;
  uint32_t format_version_;
  bool controllers_;
  std::string log_path_;
  StepRecord record_;  // of the step the simulation takes next, or has just taken
  ResimulateReport* report_;
  int64_t last_checked_ = -1;
};

}  // namespace

std::string ResimulateReport::Describe() const {
  if (divergence) {
    const Divergence& d = *divergence;
    return fmt::format(
        "diverged at step {} (t = {:.17g} s): {}{}{}: logged {:.17g}, simulated {:.17g}", d.step,
        d.time_sec, d.field,
        d.field.rfind("size of ", 0) == 0 || d.field == "step" || d.field == "time_sec"
            ? std::string()
            : fmt::format("[{}]", d.index),
        d.what.empty() ? std::string() : " (" + d.what + ")", d.logged, d.simulated);
  }
  if (interrupted)
    return fmt::format("stopped after {} steps (bit-exact so far, to step {})", steps_checked,
                       last_step);
  if (damage)
    return fmt::format(
        "damaged log, not verified past step {}: {} ({} steps before it bit-exact; "
        "expected an undamaged log with its end chunk)",
        last_step, *damage, steps_checked);
  if (steps_checked != steps_logged)
    return fmt::format("not verified: {} of {} logged steps checked (to step {})", steps_checked,
                       steps_logged, last_step);
  return fmt::format("bit-exact ({} steps)", steps_checked);
}

bool ResimulateReport::bit_exact() const {
  return !divergence && !interrupted && !damage && steps_checked == steps_logged;
}

ResimulateReport ResimulateLog(const ResimulateOptions& options) {
  const auto t_start = std::chrono::steady_clock::now();
  RunLogReader reader = RunLogReader::Open(options.log_path, RunLogReadMode::kRecover);
  const RunLogHeader& header = reader.header();
  ResimulateReport report;
  const auto warn = [&](const std::string& w) {
    spdlog::warn("resimulate: {}", w);
    report.warnings.push_back(w);
  };
  // a damaged log is checked up to its damage and then reported as damaged, never bit-exact
  report.damage = reader.damage();
  report.steps_logged = reader.num_steps();
  if (reader.damage()) warn(options.log_path + ": " + *reader.damage() + "; checking up to there");
  for (const std::string& w : ChangedAssets(header))
    warn(w + "; the resimulation will likely diverge");

  // commands a bridge carried out (docs/run-log.md, "command" events) are not re-injected:
  // with the controllers on none may be in the log; with the logged ctrl applied only those
  // that change the state itself (not through ctrl) make the log irreproducible
  const bool controllers = options.mode == ResimulateMode::kControllers;
  {
    int64_t commands = 0, first = -1, state_changes = 0, first_state_change = -1;
    std::string first_cmd, state_cmd;
    for (const EventRecord& e : reader.Events()) {
      if (e.kind != "command") continue;
      const nlohmann::json payload = nlohmann::json::parse(e.payload, nullptr, false);
      const std::string cmd =
          payload.is_object() && payload.contains("cmd") && payload["cmd"].is_string()
              ? payload["cmd"].get<std::string>()
              : "";
      if (commands++ == 0) {
        first = e.step;
        first_cmd = cmd;
      }
      if (cmd == "set_mocap" || cmd == "reset") {
        if (state_changes++ == 0) {
          first_state_change = e.step;
          state_cmd = cmd;
        }
      }
    }
    const std::string named = first_cmd.empty() ? "" : ", '" + first_cmd + "',";
    if (controllers && commands > 0)
      throw ConfigError(options.log_path, 0, "--resimulate",
                        fmt::format("the log holds {} command event(s) (the first{} at step {}); "
                                    "re-injecting commands is not supported yet; expected "
                                    "--resimulate ctrl, which applies the logged ctrl with the "
                                    "controllers off",
                                    commands, named, first));
    if (!controllers && state_changes > 0)
      throw ConfigError(options.log_path, 0, "--resimulate",
                        fmt::format("the log holds {} command event(s) that change the state "
                                    "itself (the first, '{}', at step {}); they are not "
                                    "re-injected and the logged ctrl does not cover them, so "
                                    "this run cannot be resimulated; expected a log without "
                                    "set_mocap or reset commands",
                                    state_changes, state_cmd, first_state_change));
  }

  // the output folder, as `run` prepares its own; left as found if the set-up fails
  namespace fs = std::filesystem;
  const bool write = !options.out_dir.empty();
  const fs::path out = options.out_dir;
  OutputLock out_lock;  // held for the whole resimulation (output/output_lock.h)
  std::optional<SetupRollback> rollback;
  if (write) {
    RefuseOutputFolderHoldingLog(options.out_dir, options.log_path);
    std::error_code exists_ec;
    const bool out_existed = fs::exists(fs::symlink_status(out, exists_ec));
    out_lock = PrepareOutputFolder(out, options.force, "--out");
    rollback.emplace(out, !out_existed);
  }

  // the recorded world as `run` set it up (its adversity preset's NPCs included)
  const WorldConfig world = RecordedWorld(header);
  SessionOptions session_options;
  const RecordedRunFlags recorded_flags = ParseRecordedRunFlags(header.command_line);
  session_options.adversity = recorded_flags.adversity;
  session_options.reserve_live_npcs = recorded_flags.live;
  session_options.add_controllers = controllers;
  session_options.build_renderer = false;
  Session session(world, session_options);
  std::unique_ptr<MetricsSink> metrics;
  try {
    if (write)
      metrics = MakeMetricsSink(world, session.sim(), out.string(), MetricsMode::kDynamics);
  } catch (const ConfigError& e) {
    throw LocateInWorld(world, e);  // the recorded world's `metrics:` line
  }
  Simulation& sim = session.sim();
  CheckLoggedTimestep(header, sim, options.log_path);
  const RunLogLayout& layout = header.layout;
  const StateMap map(layout, RunLogLayoutOf(sim), options.log_path);
  if (!map.identity())
    throw ConfigError(options.log_path, 0, "",
                      "the recorded world composes today to a model whose state layout differs "
                      "from the log's (a mocap body or body was added, removed or renamed); "
                      "expected the recorded model");
  if (controllers && sim.num_controllers() != layout.num_controllers)
    throw ConfigError(options.log_path, 0, "",
                      fmt::format("the recorded world has {} controller(s) today; the log "
                                  "records {}",
                                  sim.num_controllers(), layout.num_controllers));

  StepRecord first;
  if (!reader.NextStep(&first))
    throw ConfigError(options.log_path, 0, "", "the log holds no step; expected step 0 first");
  if (first.step != 0)
    throw ConfigError(options.log_path, 0, "",
                      fmt::format("the log's first step is {}; expected step 0 (the initial "
                                  "state) to resimulate from",
                                  first.step));

  // the live changes of the run (live/live_effects.h) at their steps: those that moved or
  // parked NPCs changed the physics from there
  LiveEffects live(session);
  for (const EventRecord& e : reader.Events()) {
    if (e.kind != "live") continue;
    ScheduleRecordedLiveChange(e, options.log_path, &live);
  }

  // ctrl mode: the ctrl of the initial state as logged (the controllers' first update, which
  // the recording run computed before its first snapshot: PhysicsSource)
  if (!controllers) {
    std::span<double> ctrl = sim.ctrl();
    if (first.ctrl.size() != ctrl.size())
      throw ConfigError(options.log_path, 0, "", "logged ctrl has another size than the model's");
    std::copy(first.ctrl.begin(), first.ctrl.end(), ctrl.begin());
  }

  // the pipeline: physics -> SimLoop -> the check (+ the metrics and run.json)
  LogCheck check(&reader, layout, controllers, options.log_path, std::move(first), &report);
  PhysicsSourceOptions physics_options;
  physics_options.before_step = [&check](Simulation& s) { return check.BeforeStep(s); };
  PhysicsSource physics(&sim, physics_options);
  SimLoopOptions loop_options;
  loop_options.stop_request = options.stop_request;
  SimLoop loop(&physics, loop_options);
  loop.AddSink(&live);  // first: a change applies before the check sees its step
  loop.AddSink(&check);
  if (metrics) loop.AddSink(metrics.get());
  std::optional<ManifestSink> manifest;
  if (write) {
    manifest.emplace(out.string(), [&](const LoopFinish& f) {
      std::map<std::string, double> timings;
      timings["compose_sec"] = session.timings().compose_sec;
      timings["load_sec"] = session.timings().load_sec;
      timings["scene_build_sec"] = session.timings().scene_build_sec;
      timings["physics_sec"] = physics.busy_sec();
      timings["total_sec"] =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
      RunManifest m;
      m.world_file = header.world_file.empty() ? header.model_file : header.world_file;
      m.seed = world.seed;
      m.penumbra_version = PENUMBRA_VERSION;
      m.mujoco_version = MujocoVersion();
      m.command_line = options.command_line;
      m.sim_duration_sec = f.time_sec;
      m.interrupted = f.reason == LoopEndReason::kStopRequested;
      m.timings_sec = timings;
      m.peak_resident_memory_mib = PeakResidentMemoryMiB();
      m.adversity = session.effects().PresetLabel();
      m.effects = session.effects().EffectLabels();
      m.agents = session.effects().AgentLabels();
      ReplayManifest r;
      r.log = options.log_path;
      r.mode = controllers ? "resimulate" : "resimulate ctrl";
      r.first_step = 0;
      r.last_step = report.last_step;
      r.warnings = report.warnings;
      report.interrupted = m.interrupted;
      r.verdict = report.Describe();
      m.replay = std::move(r);
      if (metrics) m.metrics_json = metrics->SummaryJson();  // its OnFinish ran before
      return m;
    });
    loop.AddSink(&*manifest);
  }
  if (rollback) rollback->Dismiss();
  const LoopFinish finish = loop.Run();
  if (finish.error) std::rethrow_exception(finish.error);
  report.interrupted = finish.reason == LoopEndReason::kStopRequested;
  return report;
}

}  // namespace penumbra
