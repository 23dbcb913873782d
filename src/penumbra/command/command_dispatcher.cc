#include "penumbra/command/command_dispatcher.h"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <future>
#include <limits>
#include <memory>

#include "penumbra/command/run_description.h"
#include "penumbra/control/joint_controller.h"
#include "penumbra/control/twist_command.h"
#include "penumbra/control/waypoint_follower.h"
#include "penumbra/core/build_info.h"
#include "penumbra/core/error.h"

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

const std::vector<std::string>& Names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n = {
        "hello",      "model_info",      "get_state",           "step",      "set_ctrl",
        "twist",      "joint_targets",   "waypoints",           "set_mocap", "reset",
        "pause",      "resume",          "set_realtime_factor", "stop",      "set_adversity",
        "set_effect", "start_recording", "stop_recording"};
    std::sort(n.begin(), n.end());
    return n;
  }();
  return names;
}

}  // namespace

std::vector<std::string> CommandDispatcher::CommandNames() { return Names(); }

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
    Target t{i, ControllerRobot(c), c.type(), 0};
    if (const auto* pd = dynamic_cast<const JointPdController*>(&c))
      t.joints = static_cast<int>(pd->params().servo.joints.size());
    targets_.push_back(t);
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
    const auto& names = Names();
    if (!std::binary_search(names.begin(), names.end(), name))
      throw CommandError(
          command_code::kUnknownCommand, "cmd",
          fmt::format("unknown command '{}'; expected one of: {}", name, JoinNames(names)));
    cmd = name;
    RequestReader rd(request);
    // replies from the loop thread get "cmd" and "id" too (the lambda owns copies)
    Done reply = [cmd, id, done](json r) {
      r["cmd"] = cmd;
      if (id) r["id"] = *id;
      done(std::move(r));
    };
    Handle(name, rd, reply);
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
    const auto cmds = ControllerCommands(t.type);
    if (std::find(cmds.begin(), cmds.end(), command) == cmds.end()) continue;
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

void CommandDispatcher::Handle(const std::string& cmd, RequestReader& rd, const Done& done) {
  RunControl& control = *control_;
  auto queue = [&](RunControl::Action action) {
    rd.CheckNoUnknown();
    control.Submit(LoggedAction(cmd, rd.request(), std::move(action)), done);
  };
  auto reply_now = [&](json fields) {
    json r = {{"ok", true}};
    for (auto& [k, v] : fields.items()) r[k] = std::move(v);
    done(std::move(r));
  };

  if (cmd == "hello") {
    const int64_t protocol = rd.Int("protocol", std::numeric_limits<int64_t>::min(),
                                    std::numeric_limits<int64_t>::max());
    rd.String("client", "");
    rd.CheckNoUnknown();
    if (protocol != kCommandProtocolVersion)
      throw CommandError(command_code::kVersionMismatch, "protocol",
                         fmt::format("this server speaks protocol version {}, the client {}; "
                                     "use a client of version {} (docs/zmq-protocol.md)",
                                     kCommandProtocolVersion, protocol, kCommandProtocolVersion));
    reply_now({{"protocol", kCommandProtocolVersion},
               {"server", "penumbra"},
               {"version", PENUMBRA_VERSION},
               {"mode", lockstep_ ? "lockstep" : "free"},
               {"paused", control.paused()},
               {"step", control.boundary_step()},
               {"time_sec", control.boundary_time_sec()},
               {"timestep_sec", session_.sim().timestep()},
               {"end_time_sec", world_.duration_sec},
               {"commands", Names()}});
    return;
  }
  if (cmd == "model_info") {
    rd.CheckNoUnknown();
    reply_now(model_info_);
    return;
  }
  if (cmd == "get_state") {
    queue([&control](Simulation& sim) { return control.StateJson(sim); });
    return;
  }
  if (cmd == "step") {
    const int64_t n = rd.Int("n", 1, 1000000, 1);
    const bool state = rd.Bool("state", false);
    rd.CheckNoUnknown();
    control.RequestSteps(n, state, done);
    return;
  }
  if (cmd == "set_ctrl") {
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
    queue([values = std::move(values)](Simulation& sim) {
      std::span<double> ctrl = sim.ctrl();
      for (const auto& [i, x] : values) ctrl[i] = x;
      return StepTime(sim);
    });
    return;
  }
  if (cmd == "twist") {
    const Target& t = FindTarget(rd, "twist");
    const bool clear = rd.Bool("clear", false);
    double vx = 0, vy = 0, yaw_rate = 0;
    if (clear) {
      for (const char* f : {"vx", "vy", "yaw_rate"})
        if (rd.Has(f))
          throw CommandError(
              command_code::kBadField, f,
              fmt::format("'{}' given with 'clear': true; clear takes no values", f));
    } else {
      vx = rd.Real("vx", -kMaxSpeed, kMaxSpeed, 0.0);
      vy = rd.Real("vy", -kMaxSpeed, kMaxSpeed, 0.0);
      yaw_rate = rd.Real("yaw_rate", -kMaxSpeed, kMaxSpeed, 0.0);
      if (t.type == "waypoint_follower" && vy != 0)
        throw CommandError(command_code::kBadField, "vy",
                           fmt::format("robot '{}' (waypoint_follower, differential drive) cannot "
                                       "move sideways; vy must be 0",
                                       t.robot));
    }
    queue([t, clear, vx, vy, yaw_rate](Simulation& sim) {
      Controller& c = sim.mutable_controller(t.index);
      if (auto* legged = dynamic_cast<TwistCommandable*>(&c)) {
        if (clear)
          legged->ClearCommand();
        else
          legged->SetCommand(TrotCommand{vx, vy, yaw_rate});
      } else if (auto* wf = dynamic_cast<WaypointFollower*>(&c)) {
        if (clear)
          wf->ClearTwist();
        else
          wf->SetTwist(vx, yaw_rate);
      }
      json r = StepTime(sim);
      r["robot"] = t.robot;
      return r;
    });
    return;
  }
  if (cmd == "joint_targets") {
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
    queue([t, m, values = std::move(values)](Simulation& sim) {
      auto* pd = dynamic_cast<JointPdController*>(&sim.mutable_controller(t.index));
      try {
        pd->SetCommand(JointCommand{m, values});
      } catch (const Error& e) {
        throw CommandError(command_code::kBadField, "mode", e.what());
      }
      json r = StepTime(sim);
      r["robot"] = t.robot;
      return r;
    });
    return;
  }
  if (cmd == "waypoints") {
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
      points.emplace_back(RequestReader::RealValue(pts[i][0], f + "[0]"),
                          RequestReader::RealValue(pts[i][1], f + "[1]"));
    }
    const bool loop = rd.Bool("loop", false);
    queue([t, points = std::move(points), loop](Simulation& sim) {
      Controller& c = sim.mutable_controller(t.index);
      if (auto* legged = dynamic_cast<TwistCommandable*>(&c))
        legged->SetWaypoints(points, loop);
      else if (auto* wf = dynamic_cast<WaypointFollower*>(&c))
        wf->SetWaypoints(points, loop);
      json r = StepTime(sim);
      r["robot"] = t.robot;
      return r;
    });
    return;
  }
  if (cmd == "set_mocap") {
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
    queue([id, xyz, q](Simulation& sim) {
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
    return;
  }
  if (cmd == "reset") {
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
    queue([&control, keyframe, nmocap = static_cast<int>(mocap_names_.size())](Simulation& sim) {
      const SimState now = sim.GetState();
      SimState s = control.initial_state();
      s.step_count = now.step_count;
      s.time_sec = now.time_sec;
      s.controller_next_update = now.controller_next_update;
      sim.SetState(s);
      if (!keyframe.empty()) sim.ApplyKeyframe(keyframe, "", "keyframe");
      std::vector<int> ids(nmocap);
      for (int i = 0; i < nmocap; ++i) ids[i] = i;
      sim.ApplyMocapDrivers(ids);
      for (int i = 0; i < sim.num_controllers(); ++i) {
        Controller& c = sim.mutable_controller(i);
        if (auto* legged = dynamic_cast<TwistCommandable*>(&c)) legged->ClearCommand();
        if (auto* wf = dynamic_cast<WaypointFollower*>(&c)) wf->ClearTwist();
      }
      return StepTime(sim);
    });
    return;
  }
  if (cmd == "pause" || cmd == "resume") {
    rd.CheckNoUnknown();
    control.SetPaused(cmd == "pause", done);
    return;
  }
  if (cmd == "set_realtime_factor") {
    const double f = rd.Real("factor", 0, 1e6);
    rd.CheckNoUnknown();
    control.SetRealtimeFactor(f);
    reply_now({{"factor", f}});
    return;
  }
  if (cmd == "stop") {
    rd.CheckNoUnknown();
    control.NoteStopQueued();
    queue([&control](Simulation& sim) {
      control.RequestStop();
      return StepTime(sim);
    });
    return;
  }
  // a recording started while the run stops would get no step: refused rather than left empty
  if (cmd == "start_recording" && (control.stopping() || (live_ && live_->recorder().finished())))
    throw CommandError(command_code::kStopping, "",
                       "the run is stopping; no recording can start now");
  // set_adversity, set_effect, start_recording, stop_recording
  reply_now(HandleLive(cmd, rd));
}

RunControl::Action CommandDispatcher::LoggedAction(const std::string& cmd, const json& request,
                                                   RunControl::Action action) const {
  static const char* const kChangesSimulation[] = {"set_ctrl",  "twist",     "joint_targets",
                                                   "waypoints", "set_mocap", "reset"};
  if (!live_ ||
      std::find_if(std::begin(kChangesSimulation), std::end(kChangesSimulation),
                   [&](const char* c) { return cmd == c; }) == std::end(kChangesSimulation))
    return action;
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

json CommandDispatcher::HandleLive(const std::string& cmd, RequestReader& rd) {
  if (!live_)
    throw CommandError(command_code::kNotAvailable, "",
                       fmt::format("'{}' is not available: this run has no live controls "
                                   "(session/live_control.h)",
                                   cmd));
  // the change is checked in full here (LiveEffects / LiveRecorder throw ConfigError naming
  // the field) and applied by the loop thread at the next step boundary
  auto bad = [](const ConfigError& e, const std::string& field) {
    return CommandError(command_code::kBadField, e.key().empty() ? field : e.key(), e.problem());
  };
  if (cmd == "set_adversity") {
    const std::string preset = rd.String("preset");
    rd.CheckNoUnknown();
    try {
      live_->effects().SetAdversity(preset);
    } catch (const ConfigError& e) {
      throw bad(e, "preset");
    }
    return {{"step", live_->step()}, {"applies_from_step", live_->step() + 1}};
  }
  if (cmd == "set_effect") {
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
    try {
      live_->effects().SetEffect(effect, params);
    } catch (const ConfigError& e) {
      throw bad(e, "params");
    }
    return {{"step", live_->step()}, {"applies_from_step", live_->step() + 1}};
  }
  if (cmd == "start_recording") {
    const std::string path = rd.String("path");
    const bool sensors = rd.Bool("sensors", false);
    rd.CheckNoUnknown();
    try {
      live_->recorder().StartRecording(path, sensors);
    } catch (const ConfigError& e) {
      throw CommandError(e.key() == "recording" ? command_code::kConflict : command_code::kBadField,
                         e.key().empty() ? "path" : e.key(), e.problem());
    } catch (const std::exception& e) {
      throw CommandError(command_code::kFailed, "path", e.what());
    }
    return {{"path", path}, {"sensors", sensors}, {"from_step", live_->step() + 1}};
  }
  // stop_recording
  rd.CheckNoUnknown();
  try {
    const LiveRecording r = live_->recorder().StopRecording();
    return {{"path", r.path},
            {"bytes", r.bytes},
            {"steps", r.steps},
            {"first_step", r.first_step},
            {"last_step", r.last_step}};
  } catch (const ConfigError& e) {
    throw CommandError(command_code::kConflict, "", e.problem());
  } catch (const std::exception& e) {
    throw CommandError(command_code::kFailed, "", e.what());
  }
}

}  // namespace penumbra
