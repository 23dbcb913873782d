#include "penumbra/control/policy_controller.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <regex>
#include <set>

#include "penumbra/config/config_value.h"
#include "penumbra/control/actuator_drive.h"
#include "penumbra/control/onnx_policy_network.h"
#include "penumbra/control/policy_preset.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

// value i of a 1-or-n list
double Pick(const std::vector<double>& v, size_t i) { return v.size() == 1 ? v[0] : v[i]; }

}  // namespace

PolicyParams PolicyParams::Parse(ControllerParams& p, const std::string& prefix) {
  PolicyParams g;
  // the ONNX file, relative to the world file's folder
  std::filesystem::path path = p.String("model");
  if (path.is_relative() && !p.context().file.empty())
    path = std::filesystem::path(p.context().file).parent_path() / path;
  g.model_path = path.lexically_normal().string();
  std::error_code ec;
  const std::filesystem::file_status st = std::filesystem::status(g.model_path, ec);
  if (!std::filesystem::exists(st))
    p.Fail("model", "no such file '" + g.model_path +
                        "'; expected an ONNX policy (path relative to the world file)");
  if (!std::filesystem::is_regular_file(st))
    p.Fail("model", "'" + g.model_path + "' is " +
                        (std::filesystem::is_directory(st) ? "a directory" : "not a regular file") +
                        "; expected an ONNX policy file");

  // preset first: the keys below override it
  bool have_preset = false;
  double rate = 50;
  if (p.Has("preset")) {
    g.preset = p.String("preset");
    const auto conv = PolicyConventionFromName(g.preset);
    if (!conv)
      p.Fail("preset",
             "unknown preset '" + g.preset + "'; expected one of: " + PolicyConventionNames());
    PolicyPreset preset = MakePolicyPreset(*conv);
    g.observations = std::move(preset.observations);
    g.action = std::move(preset.action);
    rate = preset.rate_hz;
    have_preset = true;
  }

  g.base_body = prefix + p.String("base_body");
  const ConfigValue* joints = p.Raw("joints");
  if (!joints || !joints->IsSequence() || joints->size() == 0)
    p.Fail("joints", std::string(joints ? "got " + DescribeParamNode(*joints) : "missing") +
                         "; expected the policy's joints in its training order");
  if (joints->size() > 1000) p.Fail("joints", "more than 1000 joints; expected at most 1000");
  std::set<std::string> seen;
  for (size_t i = 0; i < joints->size(); ++i) {
    const ConfigValue j = (*joints)[i];
    const std::string key = "joints[" + std::to_string(i) + "]";
    if (!j.IsScalar() || j.Scalar().empty())
      p.Fail(key, "got " + DescribeParamNode(j) + "; expected a joint name");
    if (!seen.insert(j.Scalar()).second)
      p.Fail(key, "joint '" + j.Scalar() + "' is listed twice; expected each joint once");
    g.local_joints.push_back(j.Scalar());
    g.joints.push_back(prefix + j.Scalar());
  }
  if (const ConfigValue* d = p.Raw("default_joint_pos")) {
    if (d->IsSequence()) {
      for (size_t i = 0; i < d->size(); ++i)
        g.default_joint_pos.push_back(ParamNumberAt(
            p, (*d)[i], "default_joint_pos[" + std::to_string(i) + "]", "a position (rad or m)"));
      if (g.default_joint_pos.size() != g.joints.size())
        p.Fail("default_joint_pos", "has " + std::to_string(d->size()) + " values; expected " +
                                        std::to_string(g.joints.size()) + " (one per joint)");
    } else if (d->IsMap()) {
      for (const auto& kv : (*d).pairs()) {
        const std::string pat = kv.first.Scalar();
        const std::string key = "default_joint_pos." + pat;
        try {
          std::regex re(pat);
        } catch (const std::regex_error& e) {
          p.Fail(key, std::string("not a regular expression (") + e.what() +
                          "); expected an ECMAScript pattern matching joint names");
        }
        g.default_joint_patterns.push_back(
            {pat, ParamNumberAt(p, kv.second, key, "a position (rad or m)")});
      }
    } else {
      p.Fail("default_joint_pos", "got " + DescribeParamNode(*d) +
                                      "; expected a list (one per joint) or a mapping "
                                      "{pattern: value}");
    }
  }

  if (p.Has("rate_hz") && p.Has("decimation"))
    p.Fail("decimation", "given together with rate_hz; expected at most one of them");
  g.rate_hz = rate;
  if (p.Has("rate_hz")) g.rate_hz = p.Number("rate_hz", std::nullopt, 0, 100000, true);
  if (p.Has("decimation")) {
    const double d = p.Number("decimation", std::nullopt, 1, 100000);
    if (d != std::floor(d)) p.Fail("decimation", "expected a whole number of physics steps >= 1");
    g.decimation = static_cast<int>(d);
  }
  g.seed = static_cast<uint64_t>(p.Number("seed", 0, 0, 9007199254740992.0));

  if (const ConfigValue* obs = p.Raw("observations")) {
    if (!obs->IsSequence() || obs->size() == 0)
      p.Fail("observations", "got " + DescribeParamNode(*obs) +
                                 "; expected a list of terms {term: ..., scale, clip, noise, "
                                 "history}");
    g.observations.clear();
    for (size_t i = 0; i < obs->size(); ++i)
      g.observations.push_back(ObservationTermConfig::Parse(
          p, (*obs)[i], "observations[" + std::to_string(i) + "]", prefix));
  } else if (!have_preset) {
    p.Fail("observations", "missing; expected a list of observation terms or a preset (" +
                               PolicyConventionNames() + ")");
  }
  if (const ConfigValue* a = p.Raw("action")) g.action.ParseOver(p, *a, "action", prefix);
  g.script = TwistScriptParams::Parse(p);
  p.CheckNoUnknownKeys();
  return g;
}

std::vector<double> PolicyParams::DefaultPositions(const ControllerContext& c) const {
  if (!default_joint_pos.empty()) {
    if (default_joint_pos.size() != joints.size())
      throw ConfigError(c.file, c.line, c.key + ".default_joint_pos",
                        "expected one value per joint (" + std::to_string(joints.size()) + ")");
    return default_joint_pos;
  }
  std::vector<double> q(joints.size(), 0.0);
  std::vector<std::regex> res;
  for (const JointDefaultPattern& d : default_joint_patterns) res.emplace_back(d.pattern);
  for (size_t j = 0; j < local_joints.size(); ++j)
    for (size_t k = 0; k < res.size(); ++k)
      if (std::regex_match(local_joints[j], res[k])) {
        q[j] = default_joint_patterns[k].value;
        break;
      }
  return q;
}

PolicyController::PolicyController(PolicyParams params, ControllerContext context)
    : Controller(std::move(context)),
      params_(std::move(params)),
      observation_(params_.observations, params_.seed, this->context()),
      source_(params_.script) {
  const ControllerContext& c = this->context();
  auto fail = [&](const std::string& key, const std::string& problem) {
    throw ConfigError(c.file, c.line, c.key.empty() ? key : c.key + "." + key, problem);
  };
  const size_t n = params_.joints.size();
  if (n == 0) fail("joints", "empty; expected the policy's joints");
  const PolicyActionParams& a = params_.action;
  for (const auto& [name, list] :
       {std::pair<const char*, const std::vector<double>*>{"scale", &a.scale},
        {"kp", &a.kp},
        {"kd", &a.kd}})
    if (!list->empty() && list->size() != 1 && list->size() != n)
      fail(std::string("action.") + name, "has " + std::to_string(list->size()) +
                                              " values; expected 1 or " + std::to_string(n) +
                                              " (one per joint)");
  if (a.scale.empty()) fail("action.scale", "expected a scale");
  if (!a.actuators.empty() && a.actuators.size() != n)
    fail("action.actuators", "has " + std::to_string(a.actuators.size()) +
                                 " names; expected one per joint (" + std::to_string(n) + ")");
  switch (a.kind) {
    case PolicyActionKind::kJointPosition:
      if (a.kp.empty() != a.kd.empty())
        fail(a.kp.empty() ? "action.kp" : "action.kd",
             "expected both kp and kd (PD through the actuators) or neither (position servos)");
      break;
    case PolicyActionKind::kJointVelocity:
      if (!a.kp.empty())
        fail("action.kp",
             "not used by joint_velocity; expected only kd (or neither, for "
             "velocity servos)");
      break;
    case PolicyActionKind::kJointTorque:
      if (!a.kp.empty() || !a.kd.empty())
        fail(a.kp.empty() ? "action.kd" : "action.kp",
             "not used by joint_torque; expected neither kp nor kd");
      break;
  }
  if (params_.decimation <= 0 && !(params_.rate_hz > 0)) fail("rate_hz", "expected a rate > 0");
}

PolicyController::~PolicyController() = default;

std::vector<NameRequirement> PolicyController::RequiredNames() const {
  std::vector<NameRequirement> r;
  r.push_back({ModelObject::kBody, params_.base_body, "base_body"});
  for (size_t j = 0; j < params_.joints.size(); ++j)
    r.push_back({ModelObject::kJoint, params_.joints[j], "joints[" + std::to_string(j) + "]"});
  for (size_t j = 0; j < params_.joints.size(); ++j)
    r.push_back({ModelObject::kActuator,
                 params_.action.actuators.empty() ? params_.joints[j] : params_.action.actuators[j],
                 params_.action.actuators.empty() ? "joints[" + std::to_string(j) + "]"
                                                  : "action.actuators[" + std::to_string(j) + "]"});
  observation_.AppendRequiredNames(&r);
  return r;
}

void PolicyController::OnInitialize(const ModelInfo& model, const std::vector<int>& ids) {
  const ControllerContext& c = context();
  auto fail = [&](const std::string& key, const std::string& problem) {
    throw ConfigError(c.file, c.line, c.key.empty() ? key : c.key + "." + key, problem);
  };
  const int n = static_cast<int>(params_.joints.size());
  base_ = ids[0];
  qpos_.assign(n, 0);
  dof_.assign(n, 0);
  act_.assign(n, 0);
  actuator_.assign(n, ActuatorInfo{});
  for (int j = 0; j < n; ++j) {
    const JointInfo& ji = model.joints[ids[1 + j]];
    if (ji.type != JointInfo::Type::kHinge && ji.type != JointInfo::Type::kSlide)
      fail("joints[" + std::to_string(j) + "]",
           "joint '" + ji.name + "' is not a hinge or slide joint; expected 1-dof joints");
    qpos_[j] = ji.qpos_adr;
    dof_[j] = ji.dof_adr;
    act_[j] = ids[1 + n + j];
    actuator_[j] = model.actuators[act_[j]];
    const std::string akey = params_.action.actuators.empty()
                                 ? "joints[" + std::to_string(j) + "]"
                                 : "action.actuators[" + std::to_string(j) + "]";
    if (actuator_[j].joint != ids[1 + j])
      fail(akey, "actuator '" + actuator_[j].name + "' does not drive joint '" + ji.name +
                     "'; expected an actuator with a joint transmission on it");
    if (actuator_[j].gear[0] == 0) fail(akey, "actuator '" + actuator_[j].name + "' has gear 0");
  }

  // how targets reach the actuators
  const PolicyActionParams& a = params_.action;
  servo_ = (a.kind == PolicyActionKind::kJointPosition && a.kp.empty()) ||
           (a.kind == PolicyActionKind::kJointVelocity && a.kd.empty());
  for (int j = 0; j < n; ++j) {
    const std::string akey = params_.action.actuators.empty()
                                 ? "joints[" + std::to_string(j) + "]"
                                 : "action.actuators[" + std::to_string(j) + "]";
    const ActuatorInfo& ai = actuator_[j];
    if (servo_) {
      const bool pos = a.kind == PolicyActionKind::kJointPosition;
      const ActuatorDrive want =
          pos ? ActuatorDrive::kPositionServo : ActuatorDrive::kVelocityServo;
      if (ai.drive != want)
        fail(akey, "actuator '" + ai.name + "' is a " + ActuatorDriveName(ai.drive) + "; action " +
                       PolicyActionKindName(a.kind) + " without " + (pos ? "kp/kd" : "kd") +
                       " expects " +
                       (pos ? "position servos (MJCF <position>)" : "velocity servos") +
                       "; give action.kp and action.kd to drive it by PD instead");
    } else if (const auto problem = EffortDriveProblem(ai)) {
      fail(akey, *problem);
    }
  }
  default_q_ = Eigen::Map<const Eigen::VectorXd>(params_.DefaultPositions(c).data(), n);
  scale_.resize(n);
  kp_ = Eigen::VectorXd::Zero(n);
  kd_ = Eigen::VectorXd::Zero(n);
  for (int j = 0; j < n; ++j) {
    scale_[j] = Pick(a.scale, j);
    if (!a.kp.empty()) kp_[j] = Pick(a.kp, j);
    if (!a.kd.empty()) kd_[j] = Pick(a.kd, j);
  }

  // policy rate: a whole number of physics steps
  const double dt = model.timestep_sec;
  if (params_.decimation > 0) {
    decimation_ = params_.decimation;
  } else {
    const double steps = 1.0 / (params_.rate_hz * dt);
    decimation_ = static_cast<int>(std::lround(steps));
    if (decimation_ < 1 || std::abs(steps - decimation_) > 1e-6 * steps)
      fail(params_.decimation > 0 ? "decimation" : "rate_hz",
           "a policy period of " + std::to_string(1.0 / params_.rate_hz) +
               " s is not a whole number of physics steps of " + std::to_string(dt) +
               " s; expected rate_hz = 1 / (k timestep) or `decimation: k`");
  }

  // observation terms, then the network checked against their size
  std::vector<int> sensor_ids(ids.begin() + 1 + 2 * n, ids.end());
  observation_.Bind(model, base_, qpos_, dof_, default_q_, n, sensor_ids);
  network_ = LoadOnnxPolicy(params_.model_path, observation_.size(), n);
  obs_.assign(observation_.size(), 0.0f);
  out_.assign(n, 0.0f);
  action_.assign(n, 0.0);
  Reset();
}

void PolicyController::Reset() {
  observation_.Reset();
  source_ = TwistCommandSource(source_.params());
  std::fill(obs_.begin(), obs_.end(), 0.0f);
  std::fill(out_.begin(), out_.end(), 0.0f);
  std::fill(action_.begin(), action_.end(), 0.0);
  const int n = static_cast<int>(qpos_.size());
  target_ = params_.action.kind == PolicyActionKind::kJointPosition ? default_q_
                                                                    : Eigen::VectorXd::Zero(n);
  command_ = TrotCommand{};
  step_ = 0;
  tracking_ = {NAN, NAN, NAN};
}

void PolicyController::SetWaypoints(std::vector<Eigen::Vector2d> waypoints, bool loop) {
  source_.SetWaypoints(std::move(waypoints), loop, label());
}

void PolicyController::Compute(const ControlInput& in, std::span<double> ctrl) {
  const PolicyActionParams& a = params_.action;
  const int n = static_cast<int>(qpos_.size());
  if (step_ % decimation_ == 0) {
    const Pose X_WB = in.X_WB(base_);
    command_ = source_.Update(in.time_sec(), X_WB);
    ObservationContext ctx;
    ctx.input = &in;
    ctx.command = command_;
    ctx.last_action = action_;
    observation_.Assemble(ctx, obs_);
    // a non-finite observation (a diverged state, a term's scale) stops the run naming its term
    for (size_t i = 0; i < obs_.size(); ++i)
      if (!std::isfinite(obs_[i]))
        throw Error(label() + ": policy step " + std::to_string(step_) + " (t = " +
                    std::to_string(in.time_sec()) + " s): observation " + std::to_string(i) + ", " +
                    DescribeObservationElement(observation_.terms(), observation_.term_sizes(),
                                               static_cast<int64_t>(i)) +
                    ", is " + std::to_string(obs_[i]) + "; expected a finite value");
    network_->Run(obs_, out_);
    ProcessPolicyOutputs(out_, a.clip, step_, in.time_sec(), params_.joints, label(), action_);
    for (int j = 0; j < n; ++j)
      target_[j] = (a.kind == PolicyActionKind::kJointPosition ? default_q_[j] : 0.0) +
                   scale_[j] * action_[j];
    // tracking error: the command minus the base's velocity in its heading frame
    const Eigen::Matrix3d R = X_WB.linear();
    const double yaw = std::atan2(R(1, 0), R(0, 0));
    const Twist V = in.V_WB(base_);
    const double c = std::cos(yaw), s = std::sin(yaw);
    const Eigen::Vector3d v = V.tail<3>();
    tracking_ = {command_.vx - (c * v.x() + s * v.y()), command_.vy - (-s * v.x() + c * v.y()),
                 command_.yaw_rate - V[2]};
  }
  ++step_;

  const auto q = in.qpos();
  const auto qd = in.qvel();
  for (int j = 0; j < n; ++j) {
    const ActuatorInfo& ai = actuator_[j];
    const double qj = q[qpos_[j]], qdj = qd[dof_[j]];
    double u = 0;
    if (servo_) {
      u = ai.gear[0] * target_[j];
      if (ai.ctrl_limited) u = std::clamp(u, ai.ctrl_range[0], ai.ctrl_range[1]);
    } else {
      double tau = 0;
      switch (a.kind) {
        case PolicyActionKind::kJointPosition:
          tau = kp_[j] * (target_[j] - qj) - kd_[j] * qdj;
          break;
        case PolicyActionKind::kJointVelocity:
          tau = kd_[j] * (target_[j] - qdj);
          break;
        case PolicyActionKind::kJointTorque:
          tau = target_[j];
          break;
      }
      u = CtrlForEffort(ai, tau, qj, qdj);
    }
    ctrl[act_[j]] = u;
  }
}

}  // namespace penumbra
