#include "penumbra/control/joint_servo.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "penumbra/control/param_limits.h"
#include "penumbra/control/param_node.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

constexpr double kServoInf = std::numeric_limits<double>::infinity();

[[noreturn]] void Fail(const ControllerContext& c, const std::string& key,
                       const std::string& problem) {
  throw ConfigError(c.file, c.line, c.key.empty() ? key : c.key + "." + key, problem);
}

}  // namespace

JointServoParams JointServoParams::Parse(ControllerParams& p, const std::string& prefix,
                                         double default_kp, double default_kd,
                                         double default_max_velocity,
                                         double default_max_acceleration) {
  JointServoParams s;
  s.joints = ReadNameList(p, "joints", 1, prefix);
  s.actuators = ReadNameList(p, "actuators", 1, prefix);
  if (s.actuators.size() != s.joints.size())
    p.Fail("actuators", "got " + std::to_string(s.actuators.size()) + " actuators for " +
                            std::to_string(s.joints.size()) +
                            " joints; expected one actuator per joint, in the same order");
  const size_t n = s.joints.size();
  if (p.Has("output")) {
    const std::string out = p.String("output");
    if (out == "torque") {
      s.output = ServoOutput::kTorque;
    } else if (out == "position") {
      s.output = ServoOutput::kPosition;
    } else {
      p.Fail("output", "got '" + out + "'; expected torque or position");
    }
  } else {
    p.Raw("output");  // absent: only lists the key among the allowed ones in messages
  }
  auto fallback = [n](double v) -> std::optional<std::vector<double>> {
    if (v < 0) return std::nullopt;
    return std::vector<double>(n, v);
  };
  const bool torque = s.output == ServoOutput::kTorque;
  s.kp = ReadPerJoint(p, "kp", n, torque ? fallback(default_kp) : std::vector<double>(n, 0), 0,
                      kMaxParamGain);
  s.kd = ReadPerJoint(p, "kd", n, torque ? fallback(default_kd) : std::vector<double>(n, 0), 0,
                      kMaxParamGain);
  s.gravity_compensation = p.Bool("gravity_compensation", true);
  s.max_velocity = ReadPerJoint(p, "max_velocity", n, fallback(default_max_velocity), 0,
                                kMaxParamJointVelocity, true);
  s.max_acceleration = ReadPerJoint(p, "max_acceleration", n, fallback(default_max_acceleration), 0,
                                    kMaxParamJointAcceleration, true);
  if (p.Has("max_effort"))
    s.max_effort = ReadPerJoint(p, "max_effort", n, {}, 0, kMaxParamEffort, true);
  s.limit_margin = p.Number("limit_margin", 0.01, 0, kMaxParamJointValue);
  return s;
}

void JointServoParams::ValidateOrThrow(const ControllerContext& c) const {
  const size_t n = joints.size();
  if (n == 0) Fail(c, "joints", "empty; expected at least one joint");
  if (actuators.size() != n)
    Fail(c, "actuators",
         "got " + std::to_string(actuators.size()) + " actuators for " + std::to_string(n) +
             " joints; expected one per joint");
  auto check = [&](const char* key, const std::vector<double>& v, bool allow_empty, bool positive) {
    if (v.empty() && allow_empty) return;
    if (v.size() != n)
      Fail(c, key, "got " + std::to_string(v.size()) + " values; expected " + std::to_string(n));
    for (double x : v)
      if (!std::isfinite(x) || x < 0 || (positive && x == 0))
        Fail(c, key,
             "got " + std::to_string(x) + "; expected a finite number " +
                 (positive ? "> 0" : ">= 0"));
  };
  check("kp", kp, false, false);
  check("kd", kd, false, false);
  check("max_velocity", max_velocity, false, true);
  check("max_acceleration", max_acceleration, false, true);
  check("max_effort", max_effort, true, true);
  if (!(std::isfinite(limit_margin) && limit_margin >= 0))
    Fail(c, "limit_margin", "got " + std::to_string(limit_margin) + "; expected a number >= 0");
}

JointServo::JointServo(JointServoParams params, const ControllerContext& context)
    : params_(std::move(params)) {
  params_.ValidateOrThrow(context);
}

void JointServo::AppendRequiredNames(std::vector<NameRequirement>* reqs) const {
  for (size_t i = 0; i < params_.joints.size(); ++i)
    reqs->push_back({ModelObject::kJoint, params_.joints[i], "joints[" + std::to_string(i) + "]"});
  for (size_t i = 0; i < params_.actuators.size(); ++i)
    reqs->push_back(
        {ModelObject::kActuator, params_.actuators[i], "actuators[" + std::to_string(i) + "]"});
}

void JointServo::Bind(const ModelInfo& model, std::span<const int> ids,
                      const ControllerContext& c) {
  const int n = size();
  qpos_adr_.assign(n, 0);
  dof_adr_.assign(n, 0);
  actuator_.assign(n, 0);
  gear_.assign(n, 1);
  q_min_.resize(n);
  q_max_.resize(n);
  qd_max_.resize(n);
  effort_max_.resize(n);
  for (int i = 0; i < n; ++i) {
    const int j = ids[i];
    const int a = ids[n + i];
    const JointInfo& joint = model.joints[j];
    const std::string jkey = "joints[" + std::to_string(i) + "]";
    const std::string akey = "actuators[" + std::to_string(i) + "]";
    if (joint.type != JointInfo::Type::kHinge && joint.type != JointInfo::Type::kSlide)
      Fail(c, jkey,
           "joint '" + joint.name + "' is a free or ball joint; expected a hinge or slide");
    const ActuatorInfo& act = model.actuators[a];
    if (act.joint != j)
      Fail(c, akey,
           "actuator '" + act.name + "' does not drive joint '" + joint.name + "' (it drives " +
               (act.joint >= 0 ? "joint '" + model.joints[act.joint].name + "'"
                               : std::string("no joint")) +
               "); expected actuators[i] to drive joints[i] through a joint transmission");
    if (!(std::abs(act.gear[0]) > 0))
      Fail(c, akey, "actuator '" + act.name + "' has gear 0; expected a non-zero gear");
    // torque output writes efforts: a servo would read them as targets
    if (params_.output == ServoOutput::kTorque && act.drive != ActuatorDrive::kMotor)
      Fail(c, akey,
           "actuator '" + act.name + "' is a " + ActuatorDriveName(act.drive) +
               (act.drive_detail.empty() ? "" : " (" + act.drive_detail + ")") +
               "; expected a motor for output: torque (for position servos set output: position)");
    qpos_adr_[i] = joint.qpos_adr;
    dof_adr_[i] = joint.dof_adr;
    actuator_[i] = a;
    gear_[i] = act.gear[0];
    const double m = params_.limit_margin;
    if (joint.limited) {
      if (joint.range[1] - joint.range[0] <= 2 * m)
        Fail(c, "limit_margin",
             "margin " + std::to_string(m) + " leaves nothing of the range of joint '" +
                 joint.name + "'; expected a margin below half the joint range");
      q_min_[i] = joint.range[0] + m;
      q_max_[i] = joint.range[1] - m;
    } else {
      q_min_[i] = -kServoInf;
      q_max_[i] = kServoInf;
    }
    qd_max_[i] = params_.max_velocity[i];
    double effort = kServoInf;
    if (act.ctrl_limited)
      effort =
          std::max(std::abs(act.ctrl_range[0]), std::abs(act.ctrl_range[1])) * std::abs(gear_[i]);
    if (!params_.max_effort.empty()) effort = std::min(effort, params_.max_effort[i]);
    effort_max_[i] = effort;
  }
}

void JointServo::ReadState(const ControlInput& input, Eigen::VectorXd* q,
                           Eigen::VectorXd* qd) const {
  const int n = size();
  const std::span<const double> qpos = input.qpos();
  const std::span<const double> qvel = input.qvel();
  q->resize(n);
  qd->resize(n);
  for (int i = 0; i < n; ++i) {
    (*q)[i] = qpos[qpos_adr_[i]];
    (*qd)[i] = qvel[dof_adr_[i]];
  }
}

Eigen::VectorXd JointServo::ClampPosition(const Eigen::VectorXd& q) const {
  return q.cwiseMax(q_min_).cwiseMin(q_max_);
}

void JointServo::StepTowards(const Eigen::VectorXd& target, const Eigen::VectorXd& target_velocity,
                             double dt, Eigen::VectorXd* q_ref, Eigen::VectorXd* qd_ref) const {
  const int n = size();
  if (qd_ref->size() != n) qd_ref->setZero(n);
  if (dt <= 0) {
    qd_ref->setZero();
    return;
  }
  delta_.resize(n);
  double scale = 1;
  for (int i = 0; i < n; ++i) {
    delta_[i] = std::clamp(target[i], q_min_[i], q_max_[i]) - (*q_ref)[i];
    const double d = std::abs(delta_[i]);
    if (d <= 0) continue;
    const double a = params_.max_acceleration[i];
    const double v_target = target_velocity.size() == n ? std::abs(target_velocity[i]) : 0.0;
    // fastest speed from which steps slowing by a dt each still stop within d: the
    // discrete form of sqrt(2 a d)
    const double v_brake = a * dt * (std::sqrt(0.25 + 2 * d / (a * dt * dt)) - 0.5);
    const double v = std::min({qd_max_[i], std::abs((*qd_ref)[i]) + a * dt, v_target + v_brake});
    scale = std::min(scale, v * dt / d);
  }
  for (int i = 0; i < n; ++i) {
    const double step = scale * delta_[i];
    (*q_ref)[i] += step;
    (*qd_ref)[i] = step / dt;
  }
}

double JointServo::Bias(const ControlInput& input, int i) const {
  if (!params_.gravity_compensation) return 0;
  const std::span<const double> bias = input.qfrc_bias();
  if (bias.empty())
    throw Error(
        "JointServo: gravity_compensation needs ControlInput::qfrc_bias(), which this input "
        "does not provide");
  return bias[dof_adr_[i]];
}

void JointServo::Write(const ControlInput& input, const Eigen::VectorXd& q_ref,
                       const Eigen::VectorXd& qd_ref, const Eigen::VectorXd& tau_ff,
                       std::span<double> ctrl) const {
  const int n = size();
  if (params_.output == ServoOutput::kPosition) {
    last_effort_.resize(0);
    for (int i = 0; i < n; ++i)
      ctrl[actuator_[i]] = gear_[i] * std::clamp(q_ref[i], q_min_[i], q_max_[i]);
    return;
  }
  const std::span<const double> qpos = input.qpos();
  const std::span<const double> qvel = input.qvel();
  last_effort_.resize(n);
  for (int i = 0; i < n; ++i) {
    double tau = params_.kp[i] * (q_ref[i] - qpos[qpos_adr_[i]]) +
                 params_.kd[i] * (qd_ref[i] - qvel[dof_adr_[i]]) + Bias(input, i);
    if (tau_ff.size() == n) tau += tau_ff[i];
    tau = std::clamp(tau, -effort_max_[i], effort_max_[i]);
    last_effort_[i] = tau;
    ctrl[actuator_[i]] = tau / gear_[i];
  }
}

void JointServo::WriteEffort(const ControlInput& input, const Eigen::VectorXd& tau,
                             std::span<double> ctrl) const {
  const int n = size();
  last_effort_.resize(n);
  for (int i = 0; i < n; ++i) {
    const double t = std::clamp(tau[i] + Bias(input, i), -effort_max_[i], effort_max_[i]);
    last_effort_[i] = t;
    ctrl[actuator_[i]] = t / gear_[i];
  }
}

}  // namespace penumbra
