#include "penumbra/replay/state_map.h"

#include <algorithm>
#include <map>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

std::string Quoted(const std::string& name, const char* kind, size_t index) {
  return name.empty() ? "unnamed " + std::string(kind) + " #" + std::to_string(index)
                      : std::string(kind) + " '" + name + "'";
}

bool SameJoints(const std::vector<RunLogJoint>& a, const std::vector<RunLogJoint>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i) {
    if (a[i].name != b[i].name || a[i].type != b[i].type || a[i].qpos_adr != b[i].qpos_adr ||
        a[i].qpos_width != b[i].qpos_width || a[i].qvel_adr != b[i].qvel_adr ||
        a[i].qvel_width != b[i].qvel_width)
      return false;
  }
  return true;
}

// the dimensions copied whole when log and model agree, kept as the model's when the log holds
// none (a format 1 log records none of them)
constexpr StateDim kWholeIfRecorded[] = {StateDim::kNhistory, StateDim::kNeq,
                                         StateDim::kNpluginstate, StateDim::kNplastic};

// the same sizes (but the controllers', which are not mapped, and those of kWholeIfRecorded the
// log does not hold) and names
bool SameLayout(const RunLogLayout& a, const RunLogLayout& b) {
  StateDims da = a.dims(), db = b.dims();
  da[StateDim::kNumControllers] = db[StateDim::kNumControllers] = 0;
  for (const StateDim dim : kWholeIfRecorded)
    if (da[dim] == 0) db[dim] = 0;
  return da == db && SameJoints(a.joints, b.joints) && a.actuator_names == b.actuator_names &&
         a.mocap_body_names == b.mocap_body_names && a.body_names == b.body_names;
}

template <typename T>
void CheckSize(std::string_view field, const std::vector<T>& v, int64_t expected,
               const char* side) {
  if (static_cast<int64_t>(v.size()) != expected)
    throw Error("replay state map: " + std::string(side) + " " + std::string(field) + " has " +
                std::to_string(v.size()) + " entries; expected " + std::to_string(expected));
}

}  // namespace

std::vector<int> MatchNames(const std::vector<std::string>& log,
                            const std::vector<std::string>& model) {
  std::map<std::string, int> by_name;
  std::vector<int> unnamed;
  for (size_t i = 0; i < model.size(); ++i) {
    if (model[i].empty())
      unnamed.push_back(static_cast<int>(i));
    else
      by_name.emplace(model[i], static_cast<int>(i));
  }
  std::vector<int> out(log.size(), -1);
  size_t next_unnamed = 0;
  for (size_t i = 0; i < log.size(); ++i) {
    if (log[i].empty()) {
      if (next_unnamed < unnamed.size()) out[i] = unnamed[next_unnamed++];
      continue;
    }
    auto it = by_name.find(log[i]);
    if (it != by_name.end()) out[i] = it->second;
  }
  return out;
}

void StateMap::AddSpan(std::vector<Span>* spans, int src, int dst, int length) {
  if (length <= 0) return;
  // consecutive entries in both vectors become one copy
  if (!spans->empty()) {
    Span& last = spans->back();
    if (last.src + last.length == src && last.dst + last.length == dst) {
      last.length += length;
      return;
    }
  }
  spans->push_back({src, dst, length});
}

StateMap::StateMap(const RunLogLayout& log, const RunLogLayout& model, const std::string& log_name)
    : log_(log), model_(model), identity_(SameLayout(log, model)) {
  const auto fail = [&](const std::string& problem) {
    throw ConfigError(log_name, 0, "", problem);
  };
  const std::string kFixed =
      "; expected the recorded robots and models unchanged (a replay may change only what is "
      "seen: docs/replay.md)";

  // joints: both ways, same type and widths
  std::vector<std::string> log_joints, model_joints;
  for (const RunLogJoint& j : log.joints) log_joints.push_back(j.name);
  for (const RunLogJoint& j : model.joints) model_joints.push_back(j.name);
  const std::vector<int> joint_to = MatchNames(log_joints, model_joints);
  std::vector<char> model_joint_seen(model.joints.size(), 0);
  for (size_t i = 0; i < log.joints.size(); ++i) {
    const RunLogJoint& a = log.joints[i];
    if (joint_to[i] < 0)
      fail("the replay model has no " + Quoted(a.name, "joint", i) + " (" + a.type +
           ", qpos width " + std::to_string(a.qpos_width) + ") that the log records" + kFixed);
    const RunLogJoint& b = model.joints[joint_to[i]];
    model_joint_seen[joint_to[i]] = 1;
    if (a.type != b.type || a.qpos_width != b.qpos_width || a.qvel_width != b.qvel_width)
      fail("the replay model's " + Quoted(a.name, "joint", i) + " is " + b.type +
           " with qpos width " + std::to_string(b.qpos_width) + " and qvel width " +
           std::to_string(b.qvel_width) + "; the log records it as " + a.type +
           " with qpos width " + std::to_string(a.qpos_width) + " and qvel width " +
           std::to_string(a.qvel_width) + kFixed);
    AddSpan(&Spans(StateDim::kNq), a.qpos_adr, b.qpos_adr, a.qpos_width);
    AddSpan(&Spans(StateDim::kNv), a.qvel_adr, b.qvel_adr, a.qvel_width);
  }
  for (size_t j = 0; j < model.joints.size(); ++j)
    if (!model_joint_seen[j])
      fail("the replay model has " + Quoted(model.joints[j].name, "joint", j) +
           ", which the log does not record" + kFixed);

  // actuators: ctrl and act. the same actuators in the same order with the same nu and na (a
  // replay changes no robot) copy both whole: MuJoCo 4 puts a stateful actuator anywhere and
  // gives it one or more activations (actuator_actadr / actnum, which the layout does not
  // hold). otherwise actuator by actuator: one ctrl each, act for the last na actuators, one
  // activation each (MuJoCo 2.2.2's order)
  const bool same_actuators =
      log.actuator_names == model.actuator_names && log.nu == model.nu && log.na == model.na;
  if (same_actuators) {
    AddSpan(&Spans(StateDim::kNu), 0, 0, log.nu);
    AddSpan(&Spans(StateDim::kNa), 0, 0, log.na);
  } else {
    const std::vector<int> act_to = MatchNames(log.actuator_names, model.actuator_names);
    std::vector<char> model_act_seen(model.actuator_names.size(), 0);
    for (size_t i = 0; i < log.actuator_names.size(); ++i) {
      if (act_to[i] < 0)
        fail("the replay model has no " + Quoted(log.actuator_names[i], "actuator", i) +
             " that the log records" + kFixed);
      const int b = act_to[i];
      model_act_seen[b] = 1;
      AddSpan(&Spans(StateDim::kNu), static_cast<int>(i), b, 1);
      const int log_act = static_cast<int>(i) - (log.nu - log.na);
      const int model_act = b - (model.nu - model.na);
      if ((log_act >= 0) != (model_act >= 0))
        fail("the replay model's " + Quoted(log.actuator_names[i], "actuator", i) +
             (model_act >= 0 ? " has" : " has no") + " activation state; the log records it " +
             (log_act >= 0 ? "with" : "without") + " one" + kFixed);
      if (log_act >= 0) AddSpan(&Spans(StateDim::kNa), log_act, model_act, 1);
    }
    for (size_t a = 0; a < model.actuator_names.size(); ++a)
      if (!model_act_seen[a])
        fail("the replay model has " + Quoted(model.actuator_names[a], "actuator", a) +
             ", which the log does not record" + kFixed);
  }

  if (log.nuserdata != model.nuserdata)
    fail("the replay model has " + std::to_string(model.nuserdata) +
         " userdata entries; the log records " + std::to_string(log.nuserdata) + kFixed);
  AddSpan(&Spans(StateDim::kNuserdata), 0, 0, log.nuserdata);

  // history buffers, equality switches, plugin and plastic state: whole, where logged
  const StateDims log_dims = log.dims(), model_dims = model.dims();
  for (const StateDim dim : kWholeIfRecorded) {
    if (log_dims[dim] == 0) continue;
    const std::string_view name = kStateDimNames[static_cast<size_t>(dim)];
    if (log_dims[dim] != model_dims[dim])
      fail("the replay model's " + std::string(name) + " is " + std::to_string(model_dims[dim]) +
           "; the log records " + std::to_string(log_dims[dim]) + kFixed);
    AddSpan(&Spans(dim), 0, 0, static_cast<int>(log_dims[dim]));
  }

  // mocap bodies: logged ones follow the log, the model's others keep their drivers
  const std::vector<int> mocap_to = MatchNames(log.mocap_body_names, model.mocap_body_names);
  std::vector<char> model_mocap_seen(model.mocap_body_names.size(), 0);
  for (size_t i = 0; i < log.mocap_body_names.size(); ++i) {
    const int b = mocap_to[i];
    if (b < 0) {
      dropped_mocap_.push_back(log.mocap_body_names[i]);
      continue;
    }
    model_mocap_seen[b] = 1;
    AddSpan(&Spans(StateDim::kNmocap), static_cast<int>(i), b, 1);
  }
  for (size_t b = 0; b < model.mocap_body_names.size(); ++b)
    if (!model_mocap_seen[b]) unlogged_mocap_.push_back(static_cast<int>(b));

  // applied wrenches per body
  const std::vector<int> body_to = MatchNames(log.body_names, model.body_names);
  for (size_t i = 0; i < log.body_names.size(); ++i)
    if (body_to[i] >= 0) AddSpan(&Spans(StateDim::kNbody), static_cast<int>(i), body_to[i], 1);
}

void StateMap::Apply(const StepRecord& r, SimState* s) const {
  // every field but the controllers' schedule, which is not mapped
  const StateDims log_dims = log_.dims(), model_dims = model_.dims();
  const auto mapped = [](const StateFieldInfo& f) {
    return f.field != StateField::kControllerNextUpdate;
  };
  ForEachStateField(
      [&](const StateFieldInfo& f, const auto& v) {
        if (mapped(f)) CheckSize(f.name, v, StateFieldSize(f, log_dims), "logged");
      },
      r);
  ForEachStateField(
      [&](const StateFieldInfo& f, const auto& v) {
        if (mapped(f)) CheckSize(f.name, v, StateFieldSize(f, model_dims), "replay");
      },
      *s);
  s->step = r.step;
  s->time_sec = r.time_sec;
  ForEachStateField(
      [&](const StateFieldInfo& f, auto& dst, const auto& src) {
        if (!mapped(f)) return;
        // spans count units of the field's dimension (a joint's coordinates, a body)
        for (const Span& sp : spans_[static_cast<size_t>(f.dim)])
          std::copy_n(src.begin() + int64_t{f.per} * sp.src, int64_t{f.per} * sp.length,
                      dst.begin() + int64_t{f.per} * sp.dst);
      },
      *s, r);
}

}  // namespace penumbra
