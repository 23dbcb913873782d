#include "penumbra/replay/resimulate.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstring>

#include "penumbra/core/error.h"
#include "penumbra/physics/simulation.h"
#include "penumbra/replay/recorded_world.h"
#include "penumbra/replay/state_map.h"
#include "penumbra/runlog/run_log_reader.h"
#include "penumbra/session/run_log_header.h"
#include "penumbra/session/session.h"

namespace penumbra {
namespace {

// what entry i of a state field belongs to, from the log's layout
std::string EntryOwner(const RunLogLayout& l, const std::string& field, int64_t i) {
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
    if (k / width >= static_cast<int64_t>(names.size())) return "";
    return std::string(kind) + " '" + names[k / width] + "'" +
           (parts ? std::string(" ") + parts[k % width] : "");
  };
  static const char* const kXyz[] = {"x", "y", "z"};
  static const char* const kWxyz[] = {"w", "x", "y", "z"};
  static const char* const kWrench[] = {"torque x", "torque y", "torque z",
                                        "force x",  "force y",  "force z"};
  if (field == "qpos") return joint(true);
  if (field == "qvel" || field == "qacc_warmstart" || field == "qfrc_applied") return joint(false);
  if (field == "ctrl") return named(l.actuator_names, i, "actuator", 1, nullptr);
  if (field == "act") return named(l.actuator_names, i + (l.nu - l.na), "actuator", 1, nullptr);
  if (field == "xfrc_applied") return named(l.body_names, i, "body", 6, kWrench);
  if (field == "mocap_pos") return named(l.mocap_body_names, i, "mocap body", 3, kXyz);
  if (field == "mocap_quat") return named(l.mocap_body_names, i, "mocap body", 4, kWxyz);
  if (field == "controller_next_update")
    return named(l.controller_names, i, "controller", 1, nullptr);
  return "";
}

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }

// the first difference between the logged record and the simulated state, if any
std::optional<Divergence> Compare(const StepRecord& r, const SimState& s, const RunLogLayout& l,
                                  bool check_schedule) {
  Divergence d;
  d.step = r.step;
  d.time_sec = r.time_sec;
  if (r.step != s.step_count) {
    d.field = "step";
    d.logged = static_cast<double>(r.step);
    d.simulated = static_cast<double>(s.step_count);
    return d;
  }
  if (!SameBits(r.time_sec, s.time_sec)) {
    d.field = "time_sec";
    d.logged = r.time_sec;
    d.simulated = s.time_sec;
    return d;
  }
  const auto vec = [&](const char* field, const std::vector<double>& a,
                       const std::vector<double>& b) -> bool {
    if (a.size() != b.size()) {
      d.field = std::string("size of ") + field;
      d.logged = static_cast<double>(a.size());
      d.simulated = static_cast<double>(b.size());
      return true;
    }
    for (size_t i = 0; i < a.size(); ++i) {
      if (SameBits(a[i], b[i])) continue;
      d.field = field;
      d.index = static_cast<int64_t>(i);
      d.what = EntryOwner(l, field, d.index);
      d.logged = a[i];
      d.simulated = b[i];
      return true;
    }
    return false;
  };
  if (vec("qpos", r.qpos, s.qpos) || vec("qvel", r.qvel, s.qvel) || vec("act", r.act, s.act) ||
      vec("ctrl", r.ctrl, s.ctrl) || vec("qacc_warmstart", r.qacc_warmstart, s.qacc_warmstart) ||
      vec("qfrc_applied", r.qfrc_applied, s.qfrc_applied) ||
      vec("xfrc_applied", r.xfrc_applied, s.xfrc_applied) ||
      vec("mocap_pos", r.mocap_pos, s.mocap_pos) || vec("mocap_quat", r.mocap_quat, s.mocap_quat) ||
      vec("userdata", r.userdata, s.userdata))
    return d;
  if (check_schedule) {
    const auto to_d = [](const std::vector<int64_t>& v) {
      return std::vector<double>(v.begin(), v.end());
    };
    if (vec("controller_next_update", to_d(r.controller_next_update),
            to_d(s.controller_next_update)))
      return d;
  }
  return std::nullopt;
}

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
  return fmt::format("bit-exact ({} steps)", steps_checked);
}

ResimulateReport ResimulateLog(const ResimulateOptions& options) {
  RunLogReader reader = RunLogReader::Open(options.log_path, RunLogReadMode::kRecover);
  const RunLogHeader& header = reader.header();
  ResimulateReport report;
  const auto warn = [&](const std::string& w) {
    spdlog::warn("resimulate: {}", w);
    report.warnings.push_back(w);
  };
  if (reader.damage()) warn(options.log_path + ": " + *reader.damage() + "; checking up to there");
  for (const std::string& w : ChangedAssets(header))
    warn(w + "; the resimulation will likely diverge");

  const bool controllers = options.mode == ResimulateMode::kControllers;
  if (controllers) {
    int64_t commands = 0, first = -1;
    for (const EventRecord& e : reader.Events()) {
      if (e.kind != "command") continue;
      if (commands++ == 0) first = e.step;
    }
    if (commands > 0)
      throw ConfigError(options.log_path, 0, "--resimulate",
                        fmt::format("the log holds {} command event(s) (the first at step {}); "
                                    "re-injecting commands is not supported yet; expected "
                                    "--resimulate ctrl, which applies the logged ctrl with the "
                                    "controllers off",
                                    commands, first));
  }

  // the recorded world as `run` set it up (its adversity preset's NPCs included)
  const WorldConfig world = RecordedWorld(header);
  SessionOptions session_options;
  session_options.adversity = ParseRecordedRunFlags(header.command_line).adversity;
  session_options.add_controllers = controllers;
  session_options.build_renderer = false;
  Session session(world, session_options);
  Simulation& sim = session.sim();
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

  StepRecord r;
  if (!reader.NextStep(&r))
    throw ConfigError(options.log_path, 0, "", "the log holds no step; expected step 0 first");
  if (r.step != 0)
    throw ConfigError(options.log_path, 0, "",
                      fmt::format("the log's first step is {}; expected step 0 (the initial "
                                  "state) to resimulate from",
                                  r.step));
  report.divergence = Compare(r, sim.GetState(), layout, controllers);
  report.steps_checked = 1;
  report.last_step = r.step;
  while (!report.divergence && reader.NextStep(&r)) {
    if (options.stop_request && options.stop_request->load() != 0) {
      report.interrupted = true;
      break;
    }
    if (r.step != sim.step_count() + 1)
      throw ConfigError(options.log_path, 0, "",
                        fmt::format("the log skips from step {} to step {}; expected every step",
                                    sim.step_count(), r.step));
    if (!controllers) {
      // the ctrl the controllers wrote during this step, as logged after it
      std::span<double> ctrl = sim.ctrl();
      if (r.ctrl.size() != ctrl.size())
        throw ConfigError(options.log_path, 0, "", "logged ctrl has another size than the model's");
      std::copy(r.ctrl.begin(), r.ctrl.end(), ctrl.begin());
    }
    sim.Step();
    report.divergence = Compare(r, sim.GetState(), layout, controllers);
    ++report.steps_checked;
    report.last_step = r.step;
  }
  return report;
}

}  // namespace penumbra
