#include "penumbra/command/command_dispatcher.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <filesystem>
#include <future>
#include <limits>
#include <memory>

#include "penumbra/command/run_description.h"
#include "penumbra/control/controller_capabilities.h"
#include "penumbra/core/build_info.h"
#include "penumbra/core/error.h"
#include "penumbra/core/magnitude_limits.h"
#include "penumbra/core/output_path_policy.h"

namespace penumbra {
namespace {

using json = nlohmann::json;

constexpr double kMaxSpeed = 1e6;  // |twist| components accepted (m/s, rad/s): finite, sane

std::string JoinNames(const std::vector<std::string>& names) {
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "" : ", ") + n;
  return s.empty() ? "(none)" : s;
}

json StepTime(const Simulation& sim) {
  return {{"step", sim.step_count()}, {"time_sec", sim.time()}};
}

// `done` with {"ok": true} and `fields`
void ReplyNow(const CommandDispatcher::Done& done, json fields) {
  json r = {{"ok", true}};
  for (auto& [k, v] : fields.items()) r[k] = std::move(v);
  done(std::move(r));
}

}  // namespace

// the command table, sorted by name (docs/zmq-protocol.md "Commands": CommandTableTest checks
// that both agree)
std::span<const CommandDispatcher::CommandInfo> CommandDispatcher::Commands() {
  using T = CommandTiming;
  using D = CommandDispatcher;
  static constexpr std::array<CommandInfo, 18> kTable = {{
      {"get_state", T::kStepBoundary, false, &D::GetState},
      {"hello", T::kNow, false, &D::Hello},
      {"joint_targets", T::kStepBoundary, true, &D::JointTargets},
      {"model_info", T::kNow, false, &D::ModelInfo},
      {"pause", T::kStepBoundary, false, &D::PauseResume},
      {"reset", T::kStepBoundary, true, &D::Reset},
      {"resume", T::kStepBoundary, false, &D::PauseResume},
      {"set_adversity", T::kLive, false, &D::SetAdversity},
      {"set_ctrl", T::kStepBoundary, true, &D::SetCtrl},
      {"set_effect", T::kLive, false, &D::SetEffect},
      {"set_mocap", T::kStepBoundary, true, &D::SetMocap},
      {"set_realtime_factor", T::kNow, false, &D::SetRealtimeFactor},
      {"start_recording", T::kLive, false, &D::StartRecording},
      {"step", T::kStepBoundary, false, &D::Step},
      {"stop", T::kStepBoundary, false, &D::Stop},
      {"stop_recording", T::kLive, false, &D::StopRecording},
      {"twist", T::kStepBoundary, true, &D::Twist},
      {"waypoints", T::kStepBoundary, true, &D::Waypoints},
  }};
  static_assert(
      std::is_sorted(kTable.begin(), kTable.end(),
                     [](const CommandInfo& a, const CommandInfo& b) { return a.name < b.name; }),
      "the command table is sorted by name (binary search)");
  return kTable;
}

const CommandDispatcher::CommandInfo* CommandDispatcher::FindCommand(std::string_view name) {
  const std::span<const CommandInfo> table = Commands();
  const auto it =
      std::lower_bound(table.begin(), table.end(), name,
                       [](const CommandInfo& c, std::string_view n) { return c.name < n; });
  return it != table.end() && it->name == name ? &*it : nullptr;
}

std::vector<std::string> CommandDispatcher::CommandNames() {
  std::vector<std::string> names;
  for (const CommandInfo& c : Commands()) names.emplace_back(c.name);
  return names;
}

CommandDispatcher::CommandDispatcher(Session& session, const WorldConfig& world,
                                     RunControl* control, json model_info, bool lockstep,
                                     LiveControl* live)
    : session_(session),
      world_(world),
      control_(control),
      model_info_(std::move(model_info)),
      lockstep_(lockstep),
      live_(live) {
  Simulation& sim = session_.sim();
  for (int i = 0; i < sim.num_controllers(); ++i) {
    const Controller& c = sim.controller(i);
    Target t{i, ControllerRobot(c), ControllerCommands(c), 0, true, c.type()};
    if (const JointTarget* jt = AsJointTarget(c))
      t.joints = static_cast<int>(jt->command_joints().size());
    if (const TwistTarget* tt = AsTwistTarget(c)) t.lateral = tt->lateral();
    targets_.push_back(std::move(t));
  }
  for (const ActuatorInfo& a : sim.model_info().actuators) actuator_names_.push_back(a.name);
  mocap_names_ = sim.MocapBodyNames();
  for (size_t i = 0; i < mocap_names_.size(); ++i)
    mocap_driven_.push_back(sim.MocapDriven(static_cast<int>(i)));
  for (const KeyInfo& k : sim.model_info().keys) key_names_.push_back(k.name);
}

json CommandDispatcher::Call(const json& request) {
  auto promise = std::make_shared<std::promise<json>>();
  std::future<json> reply = promise->get_future();
  Dispatch(request, [promise](json r) { promise->set_value(std::move(r)); });
  return reply.get();
}

void CommandDispatcher::Dispatch(const json& request, Done done) {
  json cmd = nullptr;
  std::shared_ptr<json> id;
  // the reply: the result fields with "cmd" and "id" added
  auto finish = [&cmd, &id, &done](json r) {
    r["cmd"] = cmd;
    if (id) r["id"] = *id;
    done(std::move(r));
  };
  try {
    if (!request.is_object())
      throw CommandError(command_code::kMalformed, "",
                         fmt::format("the request is a {}; expected a map with a 'cmd' string",
                                     JsonTypeName(request)));
    if (auto it = request.find("id"); it != request.end()) id = std::make_shared<json>(*it);
    auto it = request.find("cmd");
    if (it == request.end())
      throw CommandError(command_code::kMalformed, "cmd",
                         "the request has no 'cmd'; expected {\"cmd\": NAME, ...}");
    if (!it->is_string())
      throw CommandError(command_code::kMalformed, "cmd",
                         fmt::format("'cmd' is a {}; expected a string", JsonTypeName(*it)));
    const std::string name = it->get<std::string>();
    const CommandInfo* info = FindCommand(name);
    if (!info)
      throw CommandError(command_code::kUnknownCommand, "cmd",
                         fmt::format("unknown command '{}'; expected one of: {}", name,
                                     JoinNames(CommandNames())));
    cmd = name;
    RequestReader rd(request);
    // replies from the loop thread get "cmd" and "id" too (the lambda owns copies)
    Done reply = [cmd, id, done](json r) {
      r["cmd"] = cmd;
      if (id) r["id"] = *id;
      done(std::move(r));
    };
    (this->*info->handle)(*info, rd, reply);
  } catch (const CommandError& e) {
    finish({{"ok", false}, {"error", e.ToJson()}});
  } catch (const std::exception& e) {
    finish({{"ok", false}, {"error", CommandError(command_code::kFailed, "", e.what()).ToJson()}});
  }
}

const CommandDispatcher::Target& CommandDispatcher::FindTarget(RequestReader& rd,
                                                               const std::string& command) {
  std::vector<const Target*> accepting;
  std::vector<std::string> robots;
  for (const Target& t : targets_) {
    if (std::find(t.commands.begin(), t.commands.end(), command) == t.commands.end()) continue;
    accepting.push_back(&t);
    robots.push_back(t.robot);
  }
  if (accepting.empty())
    throw CommandError(
        command_code::kNotAvailable, "",
        fmt::format(
            "no controller of this world accepts '{}' (it needs a robot "
            "with a {} controller)",
            command,
            command == "joint_targets" ? "joint_pd" : "trot_gait, policy or waypoint_follower"));
  const std::string robot = rd.String("robot", "");
  if (robot.empty()) {
    if (accepting.size() > 1)
      throw CommandError(command_code::kMissingField, "robot",
                         fmt::format("several robots accept '{}'; name one in 'robot': {}", command,
                                     JoinNames(robots)));
    return *accepting.front();
  }
  for (const Target* t : accepting)
    if (t->robot == robot) return *t;
  throw CommandError(command_code::kBadField, "robot",
                     fmt::format("no robot '{}' accepts '{}'; robots that do: {}", robot, command,
                                 JoinNames(robots)));
}

void CommandDispatcher::Queue(const CommandInfo& info, RequestReader& rd, const Done& done,
                              RunControl::Action action) {
  rd.CheckNoUnknown();
  control_->Submit(LoggedAction(info, rd.request(), std::move(action)), done);
}

void CommandDispatcher::Hello(const CommandInfo& /*info*/, RequestReader& rd, const Done& done) {
  const int64_t protocol =
      rd.Int("protocol", std::numeric_limits<int64_t>::min(), std::numeric_limits<int64_t>::max());
  rd.String("client", "");
  rd.CheckNoUnknown();
  if (protocol != kCommandProtocolVersion)
    throw CommandError(command_code::kVersionMismatch, "protocol",
                       fmt::format("this server speaks protocol version {}, the client {}; "
                                   "use a client of version {} (docs/zmq-protocol.md)",
                                   kCommandProtocolVersion, protocol, kCommandProtocolVersion));
  ReplyNow(done, {{"protocol", kCommandProtocolVersion},
                  {"server", "penumbra"},
                  {"version", PENUMBRA_VERSION},
                  {"mode", lockstep_ ? "lockstep" : "free"},
                  {"paused", control_->paused()},
                  {"step", control_->boundary_step()},
                  {"time_sec", control_->boundary_time_sec()},
                  {"timestep_sec", session_.sim().timestep()},
                  {"end_time_sec", world_.duration_sec},
                  {"commands", CommandNames()}});
}

void CommandDispatcher::ModelInfo(const CommandInfo& /*info*/, RequestReader& rd,
                                  const Done& done) {
  rd.CheckNoUnknown();
  ReplyNow(done, model_info_);
}

void CommandDispatcher::GetState(const CommandInfo& info, RequestReader& rd, const Done& done) {
  Queue(info, rd, done, [control = control_](Simulation& sim) { return control->StateJson(sim); });
}

void CommandDispatcher::Step(const CommandInfo& /*info*/, RequestReader& rd, const Done& done) {
  const int64_t n = rd.Int("n", 1, 1000000, 1);
  const bool state = rd.Bool("state", false);
  rd.CheckNoUnknown();
  control_->RequestSteps(n, state, done);
}

void CommandDispatcher::SetCtrl(const CommandInfo& info, RequestReader& rd, const Done& done) {
  const json& v = rd.Raw("ctrl");
  std::vector<std::pair<int, double>> values;
  const int nu = static_cast<int>(actuator_names_.size());
  if (v.is_array()) {
    if (static_cast<int>(v.size()) != nu)
      throw CommandError(
          command_code::kBadField, "ctrl",
          fmt::format("'ctrl' has {} values; the model has {} actuators (nu)", v.size(), nu));
    for (int i = 0; i < nu; ++i)
      values.emplace_back(i, RequestReader::RealValue(v[i], fmt::format("ctrl[{}]", i)));
  } else if (v.is_object()) {
    for (auto it = v.begin(); it != v.end(); ++it) {
      const auto found = std::find(actuator_names_.begin(), actuator_names_.end(), it.key());
      if (found == actuator_names_.end())
        throw CommandError(command_code::kBadField, "ctrl." + it.key(),
                           fmt::format("no actuator named '{}'; actuators: {}", it.key(),
                                       JoinNames(actuator_names_)));
      values.emplace_back(static_cast<int>(found - actuator_names_.begin()),
                          RequestReader::RealValue(it.value(), "ctrl." + it.key()));
    }
  } else {
    throw CommandError(command_code::kBadField, "ctrl",
                       fmt::format("'ctrl' is a {}; expected an array of nu = {} numbers or a "
                                   "map actuator name -> number",
                                   JsonTypeName(v), nu));
  }
  Queue(info, rd, done, [values = std::move(values)](Simulation& sim) {
    std::span<double> ctrl = sim.ctrl();
    for (const auto& [i, x] : values) ctrl[i] = x;
    return StepTime(sim);
  });
}

void CommandDispatcher::Twist(const CommandInfo& info, RequestReader& rd, const Done& done) {
  const Target& t = FindTarget(rd, "twist");
  const bool clear = rd.Bool("clear", false);
  double vx = 0, vy = 0, yaw_rate = 0;
  if (clear) {
    for (const char* f : {"vx", "vy", "yaw_rate"})
      if (rd.Has(f))
        throw CommandError(command_code::kBadField, f,
                           fmt::format("'{}' given with 'clear': true; clear takes no values", f));
  } else {
    vx = rd.Real("vx", -kMaxSpeed, kMaxSpeed, 0.0);
    vy = rd.Real("vy", -kMaxSpeed, kMaxSpeed, 0.0);
    yaw_rate = rd.Real("yaw_rate", -kMaxSpeed, kMaxSpeed, 0.0);
    if (!t.lateral && vy != 0)
      throw CommandError(command_code::kBadField, "vy",
                         fmt::format("robot '{}' ({}, differential drive) cannot "
                                     "move sideways; vy must be 0",
                                     t.robot, t.type));
  }
  Queue(info, rd, done, [t, clear, vx, vy, yaw_rate](Simulation& sim) {
    TwistTarget* target = AsTwistTarget(sim.mutable_controller(t.index));
    if (clear)
      target->ClearTwist();
    else
      target->SetTwist(TrotCommand{vx, vy, yaw_rate});
    json r = StepTime(sim);
    r["robot"] = t.robot;
    return r;
  });
}

void CommandDispatcher::JointTargets(const CommandInfo& info, RequestReader& rd, const Done& done) {
  const Target& t = FindTarget(rd, "joint_targets");
  const std::string mode = rd.String("mode", "position");
  JointCommand::Mode m;
  if (mode == "position")
    m = JointCommand::Mode::kPosition;
  else if (mode == "velocity")
    m = JointCommand::Mode::kVelocity;
  else if (mode == "effort")
    m = JointCommand::Mode::kEffort;
  else
    throw CommandError(
        command_code::kBadField, "mode",
        fmt::format("unknown mode '{}'; expected position, velocity or effort", mode));
  std::vector<double> values = rd.Reals("values", t.joints);
  Queue(info, rd, done, [t, m, values = std::move(values)](Simulation& sim) {
    JointTarget* target = AsJointTarget(sim.mutable_controller(t.index));
    try {
      target->SetCommand(JointCommand{m, values});
    } catch (const Error& e) {
      throw CommandError(command_code::kBadField, "mode", e.what());
    }
    json r = StepTime(sim);
    r["robot"] = t.robot;
    return r;
  });
}

void CommandDispatcher::Waypoints(const CommandInfo& info, RequestReader& rd, const Done& done) {
  const Target& t = FindTarget(rd, "waypoints");
  const json& pts = rd.Raw("points");
  if (!pts.is_array() || pts.empty())
    throw CommandError(command_code::kBadField, "points",
                       "'points' must be a non-empty array of [x, y] (world frame, m)");
  std::vector<Eigen::Vector2d> points;
  for (size_t i = 0; i < pts.size(); ++i) {
    const std::string f = fmt::format("points[{}]", i);
    if (!pts[i].is_array() || pts[i].size() != 2)
      throw CommandError(command_code::kBadField, f,
                         fmt::format("'{}' is not [x, y]; expected two numbers (m)", f));
    // inside the scene's bounds (core/magnitude_limits.h): 1e300 used to be accepted
    Eigen::Vector2d p;
    for (int a = 0; a < 2; ++a) {
      const std::string fa = fmt::format("{}[{}]", f, a);
      p[a] = RequestReader::RealValue(pts[i][a], fa);
      if (std::abs(p[a]) > kMaxPositionM)
        throw CommandError(command_code::kBadField, fa,
                           fmt::format("'{}' is {}; expected a coordinate in [-{:g}, {:g}] m", fa,
                                       p[a], kMaxPositionM, kMaxPositionM));
    }
    points.push_back(p);
  }
  const bool loop = rd.Bool("loop", false);
  Queue(info, rd, done, [t, points = std::move(points), loop](Simulation& sim) {
    AsWaypointTarget(sim.mutable_controller(t.index))->SetWaypoints(points, loop);
    json r = StepTime(sim);
    r["robot"] = t.robot;
    return r;
  });
}

void CommandDispatcher::SetMocap(const CommandInfo& info, RequestReader& rd, const Done& done) {
  const std::string body = rd.String("body");
  const auto found = std::find(mocap_names_.begin(), mocap_names_.end(), body);
  if (found == mocap_names_.end())
    throw CommandError(
        command_code::kBadField, "body",
        fmt::format("'{}' is not a mocap body; mocap bodies: {}", body, JoinNames(mocap_names_)));
  const int id = static_cast<int>(found - mocap_names_.begin());
  if (mocap_driven_[id])
    throw CommandError(command_code::kBadField, "body",
                       fmt::format("mocap body '{}' is a world-file agent that follows its own "
                                   "path; it cannot be set",
                                   body));
  const std::vector<double> xyz = rd.Reals("xyz", 3);
  std::optional<Eigen::Quaterniond> q;
  if (rd.Has("qwxyz")) {
    const std::vector<double> w = rd.Reals("qwxyz", 4);
    q = Eigen::Quaterniond(w[0], w[1], w[2], w[3]);
    if (q->norm() < 1e-9)
      throw CommandError(command_code::kBadField, "qwxyz",
                         "'qwxyz' is the zero quaternion; expected a unit quaternion w x y z");
    q->normalize();
  }
  Queue(info, rd, done, [id, xyz, q](Simulation& sim) {
    Pose X = Pose::Identity();
    X.translation() = Eigen::Vector3d(xyz[0], xyz[1], xyz[2]);
    if (q) {
      X.linear() = q->toRotationMatrix();
    } else {
      const SimState s = sim.GetState();
      X.linear() = Eigen::Quaterniond(s.mocap_quat[4 * id], s.mocap_quat[4 * id + 1],
                                      s.mocap_quat[4 * id + 2], s.mocap_quat[4 * id + 3])
                       .normalized()
                       .toRotationMatrix();
    }
    sim.SetMocapPose(id, X);
    return StepTime(sim);
  });
}

void CommandDispatcher::Reset(const CommandInfo& info, RequestReader& rd, const Done& done) {
  const std::string keyframe = rd.String("keyframe", "");
  if (!keyframe.empty() &&
      std::find(key_names_.begin(), key_names_.end(), keyframe) == key_names_.end())
    throw CommandError(command_code::kBadField, "keyframe",
                       fmt::format("the model has no keyframe '{}'; keyframes: {}", keyframe,
                                   JoinNames(key_names_)));
  const int64_t seed =
      rd.Int("seed", 0, std::numeric_limits<int64_t>::max(), static_cast<int64_t>(world_.seed));
  if (static_cast<uint64_t>(seed) != world_.seed)
    throw CommandError(command_code::kBadField, "seed",
                       fmt::format("seed {} differs from the run's seed {}: noise streams and "
                                   "effects are seeded once at the start of a run; start a new "
                                   "run with `seed: {}` in the world file",
                                   seed, world_.seed, seed));
  Queue(info, rd, done,
        [control = control_, keyframe,
         nmocap = static_cast<int>(mocap_names_.size())](Simulation& sim) {
          const SimState now = sim.GetState();
          SimState s = control->initial_state();
          s.step = now.step;
          s.time_sec = now.time_sec;
          s.controller_next_update = now.controller_next_update;
          sim.SetState(s);
          if (!keyframe.empty()) sim.ApplyKeyframe(keyframe, "", "keyframe");
          // every controller back to its just-initialized state, on a clock that restarts at 0
          sim.ResetControllers();
          // agents at the new episode's time 0 (their drivers restart them with the episode)
          std::vector<int> ids(nmocap);
          for (int i = 0; i < nmocap; ++i) ids[i] = i;
          sim.ApplyMocapDrivers(ids);
          return StepTime(sim);
        });
}

void CommandDispatcher::PauseResume(const CommandInfo& info, RequestReader& rd, const Done& done) {
  rd.CheckNoUnknown();
  control_->SetPaused(info.name == "pause", done);
}

void CommandDispatcher::SetRealtimeFactor(const CommandInfo& /*info*/, RequestReader& rd,
                                          const Done& done) {
  const double f = rd.Real("factor", 0, 1e6);
  rd.CheckNoUnknown();
  control_->SetRealtimeFactor(f);
  ReplyNow(done, {{"factor", f}});
}

void CommandDispatcher::Stop(const CommandInfo& info, RequestReader& rd, const Done& done) {
  rd.CheckNoUnknown();
  control_->NoteStopQueued();
  Queue(info, rd, done, [control = control_](Simulation& sim) {
    control->RequestStop();
    return StepTime(sim);
  });
}

RunControl::Action CommandDispatcher::LoggedAction(const CommandInfo& info, const json& request,
                                                   RunControl::Action action) const {
  if (!live_ || !info.logged) return action;
  // the request as carried out, logged at the step boundary it took effect at
  json payload = request;
  payload.erase("id");
  return [live = live_, payload = std::move(payload), action = std::move(action)](Simulation& sim) {
    const int64_t step = sim.step_count();
    const double time_sec = sim.time();
    json r = action(sim);
    live->RecordCommand(step, time_sec, payload);
    return r;
  };
}

LiveControl& CommandDispatcher::Live(const CommandInfo& info) const {
  if (!live_)
    throw CommandError(command_code::kNotAvailable, "",
                       fmt::format("'{}' is not available: this run has no live controls "
                                   "(live/live_control.h)",
                                   info.name));
  return *live_;
}

// the live changes are checked in full here (LiveEffects / LiveRecorder throw ConfigError naming
// the field) and applied by the loop thread at the next step boundary
namespace {
CommandError BadLiveField(const ConfigError& e, const std::string& field) {
  return CommandError(command_code::kBadField, e.key().empty() ? field : e.key(), e.problem());
}
}  // namespace

void CommandDispatcher::SetAdversity(const CommandInfo& info, RequestReader& rd, const Done& done) {
  LiveControl& live = Live(info);
  const std::string preset = rd.String("preset");
  rd.CheckNoUnknown();
  try {
    live.effects().SetAdversity(preset);
  } catch (const ConfigError& e) {
    throw BadLiveField(e, "preset");
  }
  ReplyNow(done, {{"step", live.step()}, {"applies_from_step", live.step() + 1}});
}

namespace {
// the absolute path of the existing regular file `client_path` (relative, no "..", ending in
// .vdb) inside the folder of `world_file`, reached without following any symbolic link; the
// errors name the path as given and the rule, never anything outside that folder
std::string ClientVdbPath(const std::string& world_file, const std::string& client_path) {
  constexpr std::string_view kExt = ".vdb";
  constexpr std::string_view kFolder = "the world file's folder";
  auto refuse = [&](const std::string& rule) {
    return CommandError(command_code::kBadField, "params.file",
                        InputPathError(client_path, rule, kExt, kFolder).what());
  };
  // the read side's words for the two rules that keep a path inside the folder
  if (!client_path.empty() && client_path.front() == '/')
    throw refuse("is absolute (starts with '/'); only files inside the folder are read");
  if (client_path == ".." || client_path.rfind("../", 0) == 0 ||
      client_path.find("/../") != std::string::npos ||
      (client_path.size() >= 3 && client_path.compare(client_path.size() - 3, 3, "/..") == 0))
    throw refuse("has a '..' component (it would leave the folder)");
  std::vector<std::string> parts;
  try {
    parts = CheckClientPath(client_path, kExt);
  } catch (const OutputPathError& e) {
    throw refuse(e.rule());
  }
  if (world_file.empty()) throw refuse("cannot be read: this run has no world file");
  std::error_code ec;
  const std::filesystem::path root = std::filesystem::absolute(world_file, ec).parent_path();
  UniqueFd top(::open(root.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (ec || top.get() < 0) throw refuse("cannot be read: the world file's folder cannot be opened");
  const UniqueFd dir = OpenFoldersNoFollow(std::move(top), parts, [&](int, size_t i, int err) {
    throw refuse(fmt::format("folder '{}' {}", SanitizeForMessage(parts[i], 256),
                             err == ENOENT ? "does not exist"
                                           : "is a symbolic link or not a folder (links are not "
                                             "followed)"));
  });
  struct stat st {};
  if (::fstatat(dir.get(), parts.back().c_str(), &st, AT_SYMLINK_NOFOLLOW) != 0)
    throw refuse(errno == ENOENT ? "does not exist" : "cannot be read");
  if (S_ISLNK(st.st_mode)) throw refuse("is a symbolic link (links are not followed)");
  if (!S_ISREG(st.st_mode)) throw refuse("is not a regular file");
  std::filesystem::path p = root;
  for (const std::string& part : parts) p /= part;
  return p.string();
}
}  // namespace

void CommandDispatcher::SetEffect(const CommandInfo& info, RequestReader& rd, const Done& done) {
  LiveControl& live = Live(info);
  const std::string effect = rd.String("effect");
  // params: null (present) removes the effect, so it is read without the null-is-missing rule
  if (!rd.Present("params"))
    throw CommandError(command_code::kMissingField, "params",
                       "missing field 'params' (a map of parameters, or null to remove)");
  const json params = rd.Has("params") ? rd.Raw("params") : json(nullptr);
  rd.CheckNoUnknown();
  if (!params.is_object() && !params.is_null())
    throw CommandError(command_code::kBadField, "params",
                       fmt::format("'params' is a {}; expected a map of the effect's "
                                   "parameters, or null to remove the effect",
                                   JsonTypeName(params)));
  json checked = params;
  // a file a client names (vdb_smoke's .vdb): inside the world file's folder only
  if (checked.is_object() && checked.contains("file") && checked["file"].is_string())
    checked["file"] = ClientVdbPath(world_.file, checked["file"].get<std::string>());
  try {
    live.effects().SetEffect(effect, checked);
  } catch (const ConfigError& e) {
    throw BadLiveField(e, "params");
  }
  ReplyNow(done, {{"step", live.step()}, {"applies_from_step", live.step() + 1}});
}

void CommandDispatcher::StartRecording(const CommandInfo& info, RequestReader& rd,
                                       const Done& done) {
  // a recording started while the run stops would get no step: refused rather than left empty
  if (control_->stopping() || (live_ && live_->recorder().finished()))
    throw CommandError(command_code::kStopping, "",
                       "the run is stopping; no recording can start now");
  LiveControl& live = Live(info);
  const std::string path = rd.String("path");
  const bool sensors = rd.Bool("sensors", false);
  rd.CheckNoUnknown();
  try {
    live.recorder().StartRecording(path, sensors);
  } catch (const ConfigError& e) {
    throw CommandError(e.key() == "recording" ? command_code::kConflict : command_code::kBadField,
                       e.key().empty() ? "path" : e.key(), e.problem());
  } catch (const std::exception& e) {
    throw CommandError(command_code::kFailed, "path", e.what());
  }
  ReplyNow(done, {{"path", path}, {"sensors", sensors}, {"from_step", live.step() + 1}});
}

void CommandDispatcher::StopRecording(const CommandInfo& info, RequestReader& rd,
                                      const Done& done) {
  LiveControl& live = Live(info);
  rd.CheckNoUnknown();
  json reply;
  try {
    const LiveRecording r = live.recorder().StopRecording();
    reply = {{"path", r.path},
             {"bytes", r.bytes},
             {"steps", r.steps},
             {"first_step", r.first_step},
             {"last_step", r.last_step}};
  } catch (const ConfigError& e) {
    throw CommandError(command_code::kConflict, "", e.problem());
  } catch (const std::exception& e) {
    throw CommandError(command_code::kFailed, "", e.what());
  }
  ReplyNow(done, std::move(reply));
}

}  // namespace penumbra
