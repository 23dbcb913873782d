#include "penumbra/control/diff_ik.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "penumbra/config/config_value.h"
#include "penumbra/control/param_check.h"
#include "penumbra/control/param_limits.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

// xyz (required unless `xyz_optional`) and rpy_deg (optional) of a pose mapping.
Pose ReadPose(ParamNode& n, bool xyz_optional, bool* has_xyz, bool* has_rpy) {
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero(), rpy = Eigen::Vector3d::Zero();
  *has_xyz = n.Has("xyz") || !xyz_optional;
  if (*has_xyz) {
    const std::vector<double> v = n.Numbers("xyz", 3, -kMaxParamPositionM, kMaxParamPositionM, "m");
    xyz = Eigen::Vector3d(v[0], v[1], v[2]);
  } else {
    n.Raw("xyz");
  }
  *has_rpy = n.Has("rpy_deg");
  if (*has_rpy) {
    const std::vector<double> v = n.Numbers("rpy_deg", 3, -360, 360, "deg");
    rpy = Eigen::Vector3d(v[0], v[1], v[2]);
  } else {
    n.Raw("rpy_deg");
  }
  return PoseFromXyzRpyDeg(xyz, rpy);
}

// parses open | close | a number
ArmCommand ReadGripper(const ConfigValue& node, const std::function<void(std::string)>& fail) {
  if (node.IsScalar()) {
    const std::string s = node.Scalar();
    if (s == "open") return ArmCommand::Gripper(ArmCommand::GripperAction::kOpen);
    if (s == "close" || s == "closed")
      return ArmCommand::Gripper(ArmCommand::GripperAction::kClose);
    double v = 0;
    if (node.ToDoubleLoose(&v) && std::isfinite(v) && std::abs(v) <= kMaxParamEffort)
      return ArmCommand::Gripper(ArmCommand::GripperAction::kValue, v);
  }
  fail("expected open, close or a ctrl value (a number in [-1e+09, 1e+09])");
  return {};
}

// log map of a rotation: axis * angle (rad), angle in [0, pi]
Eigen::Vector3d RotationLog(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.axis() * aa.angle();
}

// minimum-jerk time scaling s(tau) and ds/dtau
void MinimumJerk(double tau, double* s, double* ds) {
  const double t2 = tau * tau, t3 = t2 * tau;
  *s = t3 * (10 - 15 * tau + 6 * t2);
  *ds = 30 * t2 * (1 - 2 * tau + t2);
}

template <typename V>
void ClampNorm(V&& v, double max) {
  const double n = v.norm();
  if (n > max) v *= max / n;
}

}  // namespace

ArmCommand ArmCommand::MoveTo(const Pose& X_BT, double speed_m_s, double angular_speed_rad_s) {
  ArmCommand c;
  c.kind = Kind::kMoveTo;
  c.pose = X_BT;
  c.speed_m_s = speed_m_s;
  c.angular_speed_rad_s = angular_speed_rad_s;
  return c;
}

ArmCommand ArmCommand::MoveBy(const Pose& delta, double speed_m_s, double angular_speed_rad_s) {
  ArmCommand c = MoveTo(delta, speed_m_s, angular_speed_rad_s);
  c.kind = Kind::kMoveBy;
  return c;
}

ArmCommand ArmCommand::SetPose(const Pose& X_BT) {
  ArmCommand c;
  c.kind = Kind::kPose;
  c.pose = X_BT;
  return c;
}

ArmCommand ArmCommand::Gripper(GripperAction action, double value) {
  ArmCommand c;
  c.kind = Kind::kGripper;
  c.gripper = action;
  c.gripper_value = value;
  return c;
}

DiffIkParams DiffIkParams::Parse(ControllerParams& p, const std::string& prefix) {
  DiffIkParams d;
  d.servo = JointServoParams::Parse(p, prefix, 400, 40, 2.0, 10.0);
  const size_t n = d.servo.joints.size();
  d.site = prefix + p.String("site");
  if (p.Has("base_body")) {
    d.base_body = prefix + p.String("base_body");
  } else {
    p.Raw("base_body");
  }
  d.position_gain = p.Number("position_gain", 10, 0, kMaxParamGain, true);
  d.orientation_gain = p.Number("orientation_gain", 10, 0, kMaxParamGain, true);
  d.damping = p.Number("damping", 0.01, 0, kMaxParamGain);
  d.damping_max = p.Number("damping_max", std::max(0.1, d.damping), d.damping, kMaxParamGain);
  d.manipulability_threshold = p.Number("manipulability_threshold", 0.005, 0, kMaxParamGain, true);
  d.max_linear_speed_m_s = p.Number("max_linear_speed_m_s", 1.0, 0, kMaxParamSpeedMS, true);
  d.max_angular_speed_rad_s =
      p.Number("max_angular_speed_deg_s", 180, 0, kMaxParamAngularSpeedDegS, true) * kDegToRad;
  d.speed_m_s = p.Number("speed_m_s", 0.25, 0, kMaxParamSpeedMS, true);
  d.angular_speed_rad_s =
      p.Number("angular_speed_deg_s", 90, 0, kMaxParamAngularSpeedDegS, true) * kDegToRad;
  d.posture = ReadOptionalNumbers(p, "posture", n, -kMaxParamJointValue, kMaxParamJointValue,
                                  "rad or m, one per joint");
  d.posture_gain = p.Number("posture_gain", 0.3, 0, kMaxParamGain);
  d.limit_zone = p.Number("limit_zone", 0.2, 0, kMaxParamJointValue, true);
  d.limit_gain = p.Number("limit_gain", 5.0, 0, kMaxParamGain);
  d.max_tracking_error = p.Number("max_tracking_error", 0.2, 0, kMaxParamPositionM, true);
  d.limit_velocity_gain = p.Number("limit_velocity_gain", 5, 0, kMaxParamGain, true);
  if (p.Has("gripper_actuator")) {
    d.gripper_actuator = prefix + p.String("gripper_actuator");
    if (p.Has("gripper_open"))
      d.gripper_open = p.Number("gripper_open", std::nullopt, -kMaxParamEffort, kMaxParamEffort);
    if (p.Has("gripper_closed"))
      d.gripper_closed =
          p.Number("gripper_closed", std::nullopt, -kMaxParamEffort, kMaxParamEffort);
    if (const ConfigValue* g = p.Raw("gripper_initial"))
      d.gripper_initial = ReadGripper(*g, [&](const std::string& e) {
        p.Fail("gripper_initial", "got '" + (g->IsScalar() ? g->Scalar() : "?") + "'; " + e);
      });
  } else {
    for (const char* k : {"gripper_open", "gripper_closed", "gripper_initial"})
      if (p.Has(k)) p.Fail(k, "given without gripper_actuator; expected a gripper_actuator too");
    p.Raw("gripper_actuator");
  }
  const bool has_gripper = !d.gripper_actuator.empty();
  d.commands = ParseCommandScript<ArmCommand>(p, "commands", [&](ParamNode& item) {
    const char* verbs[] = {"move_to", "move_by", "pose", "gripper"};
    int found = 0;
    for (const char* v : verbs) found += item.Has(v) ? 1 : 0;
    if (found != 1)
      item.FailHere(std::string(found ? "got more than one of" : "missing") +
                    " move_to / move_by / pose / gripper; expected exactly one per command");
    ArmCommand c;
    if (item.Has("gripper")) {
      if (!has_gripper)
        item.Fail("gripper", "a gripper command, but no gripper_actuator is configured");
      const ConfigValue* g = item.Raw("gripper");
      return ReadGripper(*g, [&](const std::string& e) {
        item.Fail("gripper", "got '" + (g->IsScalar() ? g->Scalar() : "?") + "'; " + e);
      });
    }
    bool has_xyz = false, has_rpy = false;
    if (item.Has("pose")) {
      ParamNode pose = item.Child("pose");
      c = ArmCommand::SetPose(ReadPose(pose, false, &has_xyz, &has_rpy));
      c.has_orientation = has_rpy;
      pose.CheckNoUnknownKeys();
      return c;
    }
    const bool by = item.Has("move_by");
    ParamNode pose = item.Child(by ? "move_by" : "move_to");
    const Pose X = ReadPose(pose, by, &has_xyz, &has_rpy);
    if (by && !has_xyz && !has_rpy) pose.FailHere("empty; expected xyz (m) and/or rpy_deg (deg)");
    pose.CheckNoUnknownKeys();
    const double speed = item.Number("speed_m_s", 0, 0, kMaxParamSpeedMS);
    const double ang =
        item.Number("angular_speed_deg_s", 0, 0, kMaxParamAngularSpeedDegS) * kDegToRad;
    c = by ? ArmCommand::MoveBy(X, speed, ang) : ArmCommand::MoveTo(X, speed, ang);
    c.has_orientation = by || has_rpy;
    return c;
  });
  d.rate_hz = p.Number("rate_hz", 0, 0, kMaxParamRateHz);
  p.CheckNoUnknownKeys();
  return d;
}

void DiffIkParams::ValidateOrThrow(const ControllerContext& c) const {
  servo.ValidateOrThrow(c);
  const ParamCheck check(c);
  if (site.empty()) check.Fail("site", "missing; expected a site name");
  check.Positive("position_gain", position_gain);
  check.Positive("orientation_gain", orientation_gain);
  check.NonNegative("damping", damping);
  if (!(std::isfinite(damping_max) && damping_max >= damping))
    check.Fail("damping_max",
               "got " + std::to_string(damping_max) + "; expected a number >= damping");
  check.Positive("manipulability_threshold", manipulability_threshold);
  check.Positive("max_linear_speed_m_s", max_linear_speed_m_s);
  check.Positive("max_angular_speed_deg_s", max_angular_speed_rad_s);
  check.Positive("speed_m_s", speed_m_s);
  check.Positive("angular_speed_deg_s", angular_speed_rad_s);
  check.NonNegative("posture_gain", posture_gain);
  check.Positive("limit_zone", limit_zone);
  check.NonNegative("limit_gain", limit_gain);
  check.Positive("max_tracking_error", max_tracking_error);
  check.Positive("limit_velocity_gain", limit_velocity_gain);
  check.NonNegative("rate_hz", rate_hz);
  if (posture && posture->size() != servo.joints.size())
    check.Fail("posture", "got " + std::to_string(posture->size()) + " values; expected " +
                              std::to_string(servo.joints.size()));
  for (size_t i = 0; i < commands.size(); ++i)
    if (commands[i].command.kind == ArmCommand::Kind::kGripper && gripper_actuator.empty())
      check.Fail("commands[" + std::to_string(i) + "].gripper",
                 "a gripper command, but no gripper_actuator is configured");
}

DiffIkController::DiffIkController(DiffIkParams params, ControllerContext context)
    : Controller(std::move(context)),
      params_(std::move(params)),
      servo_(params_.servo, this->context()),
      commands_(params_.commands) {
  params_.ValidateOrThrow(this->context());
}

std::vector<NameRequirement> DiffIkController::RequiredNames() const {
  std::vector<NameRequirement> reqs;
  servo_.AppendRequiredNames(&reqs);
  reqs.push_back({ModelObject::kSite, params_.site, "site"});
  if (!params_.base_body.empty())
    reqs.push_back({ModelObject::kBody, params_.base_body, "base_body"});
  if (!params_.gripper_actuator.empty())
    reqs.push_back({ModelObject::kActuator, params_.gripper_actuator, "gripper_actuator"});
  return reqs;
}

void DiffIkController::OnInitialize(const ModelInfo& model, const std::vector<int>& ids) {
  const int n = servo_.size();
  servo_.Bind(model, std::span<const int>(ids.data(), 2 * n), context());
  size_t k = 2 * n;
  const int site = ids[k++];
  site_body_ = model.site_body[site];
  X_bodysite_ =
      site < static_cast<int>(model.site_X_BS.size()) ? model.site_X_BS[site] : Pose::Identity();
  base_body_ = params_.base_body.empty() ? -1 : ids[k++];
  gripper_ = -1;
  if (!params_.gripper_actuator.empty()) {
    gripper_ = ids[k++];
    const ActuatorInfo& a = model.actuators[gripper_];
    const ControllerContext& c = context();
    if (!a.ctrl_limited && !(params_.gripper_open && params_.gripper_closed))
      throw ConfigError(c.file, c.line, c.key + ".gripper_actuator",
                        "actuator '" + a.name +
                            "' has no ctrlrange to take the open/closed values from; expected "
                            "gripper_open and gripper_closed");
    gripper_open_ = params_.gripper_open.value_or(a.ctrl_range[1]);
    gripper_closed_ = params_.gripper_closed.value_or(a.ctrl_range[0]);
  }
  for (int i = 0; i < n; ++i) {
    const int dof = servo_.dof_adr()[i];
    if (dof < 0 || dof >= model.nv)
      throw ConfigError(context().file, context().line, context().key + ".joints",
                        "joint dof index out of range");
  }
  J_full_.setZero(6, model.nv);
  J_.setZero(6, n);
  Ja_.setZero(6, n);
  Reset();
}

// the state of a controller just initialized: OnInitialize ends with it
void DiffIkController::Reset() {
  commands_.ClearQueue();
  commands_.Rewind();
  const int n = servo_.size();
  q_.setZero(n);
  qd_.setZero(n);
  q_ref_.setZero(n);
  qdot_.setZero(n);
  z_.setZero(n);
  dq_fixed_.setZero(n);
  tmp_n_.setZero(n);
  clamped_.assign(n, 0);
  posture_.setZero(n);
  xdot_.setZero();
  gripper_ctrl_ = 0;
  started_ = false;
  last_time_ = 0;
  moving_ = false;
  X_BS0_ = X_BG_ = X_BT_ = Pose::Identity();
  axis_S_ = Eigen::Vector3d::UnitX();
  angle_ = t0_ = duration_ = 0;
  twist_ff_B_.setZero();
  position_error_ = orientation_error_ = manipulability_ = lambda_ = 0;
}

void DiffIkController::CheckCommand(const ArmCommand& c) const {
  if (c.kind == ArmCommand::Kind::kGripper) {
    if (params_.gripper_actuator.empty())
      throw Error(label() + ": gripper command, but no gripper_actuator is configured");
    if (!std::isfinite(c.gripper_value)) throw Error(label() + ": non-finite gripper value");
    return;
  }
  if (!c.pose.matrix().allFinite() || !std::isfinite(c.speed_m_s) ||
      !std::isfinite(c.angular_speed_rad_s) || c.speed_m_s < 0 || c.angular_speed_rad_s < 0)
    throw Error(label() + ": command with a non-finite pose or a negative speed");
}

void DiffIkController::PushCommand(ArmCommand command, double at_time_sec) {
  CheckCommand(command);
  commands_.Push(std::move(command), at_time_sec);
}

void DiffIkController::SetCommand(ArmCommand command) {
  CheckCommand(command);
  commands_.Set(std::move(command));
}

void DiffIkController::StartMove(const Pose& X_BG, double speed, double angular_speed, double t) {
  X_BS0_ = X_BT_;
  X_BG_ = X_BG;
  const Eigen::AngleAxisd rel(X_BS0_.linear().transpose() * X_BG_.linear());
  angle_ = rel.angle();
  axis_S_ = rel.axis();
  const double dist = (X_BG_.translation() - X_BS0_.translation()).norm();
  const double v = speed > 0 ? speed : params_.speed_m_s;
  const double w = angular_speed > 0 ? angular_speed : params_.angular_speed_rad_s;
  // the minimum-jerk profile peaks at 1.875 times the mean speed
  duration_ = 1.875 * std::max(dist / v, angle_ / w);
  t0_ = t;
  moving_ = duration_ > 1e-9;
  if (!moving_) X_BT_ = X_BG_;
  twist_ff_B_.setZero();
}

void DiffIkController::Apply(const ArmCommand& c, double t) {
  switch (c.kind) {
    case ArmCommand::Kind::kGripper: {
      double v = c.gripper == ArmCommand::GripperAction::kOpen    ? gripper_open_
                 : c.gripper == ArmCommand::GripperAction::kClose ? gripper_closed_
                                                                  : c.gripper_value;
      gripper_ctrl_ = v;
      return;
    }
    case ArmCommand::Kind::kPose: {
      Pose goal = c.pose;
      if (!c.has_orientation) goal.linear() = X_BG_.linear();
      X_BG_ = X_BT_ = goal;
      moving_ = false;
      twist_ff_B_.setZero();
      return;
    }
    case ArmCommand::Kind::kMoveTo: {
      Pose goal = c.pose;
      if (!c.has_orientation) goal.linear() = X_BG_.linear();
      StartMove(goal, c.speed_m_s, c.angular_speed_rad_s, t);
      return;
    }
    case ArmCommand::Kind::kMoveBy: {
      // rotate about the base axes through the site, then translate (both in the base frame)
      Pose goal = Pose::Identity();
      goal.linear() = c.pose.linear() * X_BG_.linear();
      goal.translation() = X_BG_.translation() + c.pose.translation();
      StartMove(goal, c.speed_m_s, c.angular_speed_rad_s, t);
      return;
    }
  }
}

void DiffIkController::UpdateTarget(double t) {
  if (!moving_) {
    twist_ff_B_.setZero();
    return;
  }
  const double tau = (t - t0_) / duration_;
  if (tau >= 1) {
    X_BT_ = X_BG_;
    moving_ = false;
    twist_ff_B_.setZero();
    return;
  }
  double s = 0, ds = 0;
  MinimumJerk(std::max(tau, 0.0), &s, &ds);
  const double sdot = ds / duration_;
  const Eigen::Vector3d dp = X_BG_.translation() - X_BS0_.translation();
  X_BT_.translation() = X_BS0_.translation() + s * dp;
  X_BT_.linear() = X_BS0_.linear() * Eigen::AngleAxisd(s * angle_, axis_S_).toRotationMatrix();
  twist_ff_B_.head<3>() = sdot * angle_ * (X_BS0_.linear() * axis_S_);
  twist_ff_B_.tail<3>() = sdot * dp;
}

void DiffIkController::SolveDls(double dt) {
  const int n = servo_.size();
  const Eigen::VectorXd& lo = servo_.q_min();
  const Eigen::VectorXd& hi = servo_.q_max();

  // manipulability of the full Jacobian sets the damping (Nakamura and Hanafusa)
  Eigen::Matrix<double, 6, 6> A = J_ * J_.transpose();
  llt_.compute(A);
  double det = 1;
  for (int r = 0; r < 6; ++r) det *= llt_.matrixLLT()(r, r);
  manipulability_ = llt_.info() == Eigen::Success ? std::abs(det) : 0;  // sqrt(det(J J^T))
  const double w0 = params_.manipulability_threshold;
  double lambda2 = params_.damping * params_.damping;
  if (manipulability_ < w0) {
    const double f = 1 - manipulability_ / w0;
    lambda2 += (params_.damping_max * params_.damping_max - lambda2) * f * f;
  }
  lambda_ = std::sqrt(lambda2);

  // secondary task: posture and joint-limit avoidance (gradient projection)
  for (int i = 0; i < n; ++i) {
    double g = 0;
    const double zone = params_.limit_zone;
    if (q_ref_[i] < lo[i] + zone) g = lo[i] + zone - q_ref_[i];
    if (q_ref_[i] > hi[i] - zone) g = hi[i] - zone - q_ref_[i];
    z_[i] = params_.posture_gain * (posture_[i] - q_ref_[i]) + params_.limit_gain * g;
  }

  std::fill(clamped_.begin(), clamped_.end(), 0);
  dq_fixed_.setZero();
  Eigen::Matrix<double, 6, 1> r;
  for (int iter = 0; iter <= n; ++iter) {
    Ja_ = J_;
    for (int i = 0; i < n; ++i)
      if (clamped_[i]) {
        Ja_.col(i).setZero();
        tmp_n_[i] = 0;
      } else {
        tmp_n_[i] = z_[i];
      }
    r.noalias() = xdot_ - J_ * dq_fixed_;
    A.noalias() = Ja_ * Ja_.transpose();
    A.diagonal().array() += lambda2;
    llt_.compute(A);
    // qdot = Ja# r + (I - Ja# Ja) z
    r.noalias() -= Ja_ * tmp_n_;
    qdot_.noalias() = Ja_.transpose() * llt_.solve(r);
    qdot_ += tmp_n_;
    for (int i = 0; i < n; ++i)
      if (clamped_[i]) qdot_[i] = dq_fixed_[i];
    if (dt <= 0) break;
    // velocity damper: towards a bound at most beta times the distance left (and never
    // past it within this step)
    const double beta = std::min(params_.limit_velocity_gain, 1.0 / dt);
    bool again = false;
    for (int i = 0; i < n; ++i) {
      if (clamped_[i]) continue;
      const double up = beta * std::max(0.0, hi[i] - q_ref_[i]);
      const double down = beta * std::min(0.0, lo[i] - q_ref_[i]);
      if (qdot_[i] > up) {
        clamped_[i] = 1;
        dq_fixed_[i] = up;
        again = true;
      } else if (qdot_[i] < down) {
        clamped_[i] = 1;
        dq_fixed_[i] = down;
        again = true;
      }
    }
    if (!again) break;
  }

  // joint speed limits: one factor for all joints keeps the direction of qdot
  double scale = 1;
  for (int i = 0; i < n; ++i) {
    const double v = std::abs(qdot_[i]);
    if (v > servo_.qd_max()[i]) scale = std::min(scale, servo_.qd_max()[i] / v);
  }
  qdot_ *= scale;
}

void DiffIkController::Compute(const ControlInput& input, std::span<double> ctrl) {
  const double t = input.time_sec();
  const int n = servo_.size();
  servo_.ReadState(input, &q_, &qd_);
  const Pose X_WBase = base_body_ >= 0 ? input.X_WB(base_body_) : Pose::Identity();
  const Pose X_WS = input.X_WB(site_body_) * X_bodysite_;
  if (!started_) {
    started_ = true;
    last_time_ = t;
    q_ref_ = servo_.ClampPosition(q_);
    qdot_.setZero();
    if (params_.posture) {
      for (int i = 0; i < n; ++i) posture_[i] = (*params_.posture)[i];
    } else {
      posture_ = q_ref_;
    }
    X_BT_ = X_BG_ = X_WBase.inverse() * X_WS;
    moving_ = false;
    twist_ff_B_.setZero();
    if (gripper_ >= 0) Apply(params_.gripper_initial, t);
  }
  commands_.Poll(t, [&](const ArmCommand& c) { Apply(c, t); });
  const double dt = std::max(0.0, t - last_time_);
  last_time_ = t;
  UpdateTarget(t);

  // Cartesian error at the measured pose, world frame
  const Pose X_WT = X_WBase * X_BT_;
  const Eigen::Vector3d e_rot = RotationLog(X_WT.linear() * X_WS.linear().transpose());
  const Eigen::Vector3d e_pos = X_WT.translation() - X_WS.translation();
  orientation_error_ = e_rot.norm();
  position_error_ = e_pos.norm();
  const Eigen::Matrix3d& R_WBase = X_WBase.linear();
  xdot_.head<3>() = R_WBase * twist_ff_B_.head<3>() + params_.orientation_gain * e_rot;
  xdot_.tail<3>() = R_WBase * twist_ff_B_.tail<3>() + params_.position_gain * e_pos;
  ClampNorm(xdot_.head<3>(), params_.max_angular_speed_rad_s);
  ClampNorm(xdot_.tail<3>(), params_.max_linear_speed_m_s);

  input.Jacobian(site_body_, X_WS.translation(), &J_full_);
  for (int i = 0; i < n; ++i) J_.col(i) = J_full_.col(servo_.dof_adr()[i]);
  SolveDls(dt);

  const double e_max = params_.max_tracking_error;
  for (int i = 0; i < n; ++i) {
    double next = q_ref_[i] + qdot_[i] * dt;
    next = std::clamp(next, q_[i] - e_max, q_[i] + e_max);
    next = std::clamp(next, servo_.q_min()[i], servo_.q_max()[i]);
    q_ref_[i] = next;
  }
  servo_.Write(input, q_ref_, qdot_, {}, ctrl);
  if (gripper_ >= 0) ctrl[gripper_] = gripper_ctrl_;
}

}  // namespace penumbra
