#include "penumbra/control/trot_gait.h"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include "penumbra/config/config_value.h"
#include "penumbra/control/actuator_drive.h"
#include "penumbra/control/param_check.h"
#include "penumbra/control/param_limits.h"
#include "penumbra/control/pure_pursuit.h"
#include "penumbra/control/quadruped_swing_trajectory.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

constexpr double kGaitInf = std::numeric_limits<double>::infinity();
constexpr double kGravity = 9.81;
// reference heading / position may lead the robot by at most this much (anti-windup)
constexpr double kMaxHeadingLead = 0.3;
constexpr double kMaxPositionLead = 0.1;
// swing targets end this far below the estimated ground, so the foot surely lands
constexpr double kTouchdownDepth = 0.005;
// phase offsets of FR, FL, RR, RL: the diagonals FR+RL and FL+RR alternate
constexpr std::array<double, 4> kPhaseOffset = {0.0, 0.5, 0.5, 0.0};

// a wrapped into [-pi, pi)
double GaitWrapAngle(double a) { return a - 2 * M_PI * std::floor((a + M_PI) / (2 * M_PI)); }

std::string NameAt(ControllerParams& p, const ConfigValue& n, const std::string& key) {
  if (!n.IsScalar() || n.Scalar().empty())
    p.Fail(key, "got " + DescribeParamNode(n) + "; expected a name");
  return n.Scalar();
}

// X_AB for body b below ancestor a, composed from the rest frames (qpos0), or nullopt when
// a is not an ancestor of b.
std::optional<Pose> RestFrame(const ModelInfo& m, int a, int b) {
  Pose X = Pose::Identity();
  while (b != a) {
    if (b <= 0) return std::nullopt;
    X = m.body_X_PB[b] * X;
    b = m.body_parent[b];
  }
  return X;
}

}  // namespace

TrotGaitParams TrotGaitParams::Parse(ControllerParams& p, const std::string& prefix) {
  TrotGaitParams g;
  g.base_body = prefix + p.String("base_body");

  // legs: exactly FR, FL, RR, RL, each a mapping of names and conventions
  const ConfigValue* legs = p.Raw("legs");
  const std::string legs_expected =
      "expected a mapping with the legs FR, FL, RR, RL, each {hip, thigh, calf, foot, "
      "signs, offsets_rad, actuators}";
  if (!legs) p.Fail("legs", "missing; " + legs_expected);
  if (!legs->IsMap()) p.Fail("legs", "got " + DescribeParamNode(*legs) + "; " + legs_expected);
  for (const auto& kv : (*legs).pairs()) {
    const std::string k = kv.first.Scalar();
    if (std::find_if(kLegNames.begin(), kLegNames.end(), [&](const char* n) { return k == n; }) ==
        kLegNames.end())
      p.Fail("legs." + k, "unknown leg '" + k + "'; expected only FR, FL, RR, RL");
  }
  for (int i = 0; i < 4; ++i) {
    const std::string key = std::string("legs.") + kLegNames[i];
    const ConfigValue n = (*legs)[kLegNames[i]];
    if (!n) p.Fail(key, "missing; " + legs_expected);
    if (!n.IsMap())
      p.Fail(key, "got " + DescribeParamNode(n) + "; expected {hip, thigh, calf, foot, ...}");
    static const std::set<std::string> kKeys = {"hip",   "thigh",       "calf",     "foot",
                                                "signs", "offsets_rad", "actuators"};
    for (const auto& kv : n.pairs())
      if (!kKeys.count(kv.first.Scalar()))
        p.Fail(key + "." + kv.first.Scalar(),
               "unknown key; expected only hip, thigh, calf, foot, signs, offsets_rad, actuators");
    TrotLegConfig& leg = g.legs[i];
    auto name = [&](const char* k) {
      if (!n[k]) p.Fail(key + "." + k, "missing; expected a name");
      return prefix + NameAt(p, n[k], key + "." + k);
    };
    leg.hip = name("hip");
    leg.thigh = name("thigh");
    leg.calf = name("calf");
    leg.foot = name("foot");
    leg.actuators = {leg.hip, leg.thigh, leg.calf};
    if (n["actuators"]) {
      const ConfigValue a = n["actuators"];
      if (!a.IsSequence() || a.size() != 3)
        p.Fail(key + ".actuators",
               "got " + DescribeParamNode(a) + "; expected [hip, thigh, calf] names");
      for (int k = 0; k < 3; ++k)
        leg.actuators[k] = prefix + NameAt(p, a[k], key + ".actuators[" + std::to_string(k) + "]");
    }
    if (n["signs"]) {
      const ConfigValue s = n["signs"];
      if (!s.IsSequence() || s.size() != 3)
        p.Fail(key + ".signs",
               "got " + DescribeParamNode(s) + "; expected [s_hip, s_thigh, s_calf], each 1 or -1");
      for (int k = 0; k < 3; ++k) {
        const std::string sk = key + ".signs[" + std::to_string(k) + "]";
        const double v = ParamNumberAt(p, s[k], sk, "1 or -1");
        if (v != 1 && v != -1) p.Fail(sk, "got " + s[k].Scalar() + "; expected 1 or -1");
        leg.signs[k] = v;
      }
    }
    if (n["offsets_rad"]) {
      const ConfigValue o = n["offsets_rad"];
      if (!o.IsSequence() || o.size() != 3)
        p.Fail(key + ".offsets_rad", "got " + DescribeParamNode(o) + "; expected 3 angles (rad)");
      for (int k = 0; k < 3; ++k)
        leg.offsets_rad[k] = ParamNumberAt(p, o[k], key + ".offsets_rad[" + std::to_string(k) + "]",
                                           -kMaxParamJointValue, kMaxParamJointValue, "rad");
    }
  }

  // commands and waypoint route: the keys shared with the policy controller
  TwistScriptParams script = TwistScriptParams::Parse(p);
  g.commands = std::move(script.commands);
  g.waypoints = std::move(script.waypoints);
  g.loop = script.loop;
  g.speed_m_s = script.speed_m_s;
  g.max_yaw_rate_deg_s = script.max_yaw_rate_deg_s;
  g.tolerance_m = script.tolerance_m;

  g.period_sec = p.Number("period_sec", 0.36, 0.05, 5, false);
  g.duty = p.Number("duty", 0.5, 0.3, 0.8);
  g.swing_height_m = p.Number("swing_height_m", 0.08, 0, 1);
  if (p.Has("body_height_m"))
    g.body_height_m = p.Number("body_height_m", std::nullopt, 0, kMaxParamPositionM, true);
  if (p.Has("raibert_gain")) g.raibert_gain = p.Number("raibert_gain", std::nullopt, 0, 10);
  if (p.Has("max_step_m"))
    g.max_step_m = p.Number("max_step_m", std::nullopt, 0, kMaxParamPositionM, true);
  g.max_accel_m_s2 = p.Number("max_accel_m_s2", 1.5, 0, kMaxParamAccelerationMS2, true);
  g.max_yaw_accel_rad_s2 =
      p.Number("max_yaw_accel_rad_s2", 3, 0, kMaxParamAngularAccelerationRadS2, true);
  g.kp_xy = p.Number("kp_xy", 25, 0, kMaxParamGain);
  g.kd_xy = p.Number("kd_xy", 8, 0, kMaxParamGain);
  g.kp_z = p.Number("kp_z", 400, 0, kMaxParamGain);
  g.kd_z = p.Number("kd_z", 40, 0, kMaxParamGain);
  g.kp_tilt = p.Number("kp_tilt", 400, 0, kMaxParamGain);
  g.kd_tilt = p.Number("kd_tilt", 40, 0, kMaxParamGain);
  g.kp_yaw = p.Number("kp_yaw", 150, 0, kMaxParamGain);
  g.kd_yaw = p.Number("kd_yaw", 25, 0, kMaxParamGain);
  g.swing_kp = p.Number("swing_kp", 60, 0, kMaxParamGain);
  g.swing_kd = p.Number("swing_kd", 1.5, 0, kMaxParamGain);
  g.stance_kd = p.Number("stance_kd", 0.5, 0, kMaxParamGain);
  g.friction = p.Number("friction", 0.6, 0, 5, true);
  if (const ConfigValue* hold = p.Raw("hold")) {
    if (!hold->IsMap())
      p.Fail("hold", "got " + DescribeParamNode(*hold) + "; expected a mapping {actuator: ctrl}");
    for (const auto& kv : (*hold).pairs()) {
      const std::string k = kv.first.Scalar();
      g.hold.emplace_back(prefix + k, ParamNumberAt(p, kv.second, "hold." + k, -kMaxParamEffort,
                                                    kMaxParamEffort, "ctrl value"));
    }
  }
  g.rate_hz = p.Number("rate_hz", 250, 0, kMaxParamRateHz, true);
  p.CheckNoUnknownKeys();
  return g;
}

void TrotGaitParams::ValidateOrThrow(const ControllerContext& c) const {
  const ParamCheck check(c);
  if (base_body.empty()) check.Fail("base_body", "missing; expected a body name");
  std::set<std::string> joints;
  for (int i = 0; i < 4; ++i) {
    const std::string key = std::string("legs.") + kLegNames[i];
    const TrotLegConfig& l = legs[i];
    if (l.hip.empty() || l.thigh.empty() || l.calf.empty() || l.foot.empty())
      check.Fail(key, "missing names; expected hip, thigh, calf and foot");
    for (const std::string* j : {&l.hip, &l.thigh, &l.calf})
      if (!joints.insert(*j).second)
        check.Fail(key, "joint '" + *j + "' is used twice; expected 12 different joints");
    for (int k = 0; k < 3; ++k) {
      if (l.signs[k] != 1 && l.signs[k] != -1)
        check.Fail(key + ".signs", "got " + std::to_string(l.signs[k]) + "; expected 1 or -1");
      if (!std::isfinite(l.offsets_rad[k]))
        check.Fail(key + ".offsets_rad", "expected finite angles");
      if (l.actuators[k].empty()) check.Fail(key + ".actuators", "expected 3 actuator names");
    }
  }
  for (size_t i = 0; i < commands.size(); ++i) {
    const TimedTrotCommand& tc = commands[i];
    if (!(std::isfinite(tc.t_sec) && tc.t_sec >= 0) ||
        (i > 0 && !(tc.t_sec > commands[i - 1].t_sec)))
      check.Fail("commands[" + std::to_string(i) + "].t", "expected increasing times >= 0 (s)");
    if (!std::isfinite(tc.command.vx) || !std::isfinite(tc.command.vy) ||
        !std::isfinite(tc.command.yaw_rate))
      check.Fail("commands[" + std::to_string(i) + "]", "expected finite vx, vy, yaw_rate");
  }
  for (const Eigen::Vector2d& w : waypoints)
    if (!w.allFinite())
      check.Fail("waypoints", "non-finite coordinate; expected finite numbers (m)");
  if (!waypoints.empty()) {
    check.Positive("speed_m_s", speed_m_s);
    check.Positive("max_yaw_rate_deg_s", max_yaw_rate_deg_s);
    check.Positive("tolerance_m", tolerance_m);
  }
  check.Positive("period_sec", period_sec);
  if (!(duty >= 0.3 && duty <= 0.8))
    check.Fail("duty", "got " + std::to_string(duty) + "; expected a number >= 0.3 and <= 0.8");
  check.NonNegative("swing_height_m", swing_height_m);
  if (body_height_m) check.Positive("body_height_m", *body_height_m);
  if (raibert_gain) check.NonNegative("raibert_gain", *raibert_gain);
  if (max_step_m) check.Positive("max_step_m", *max_step_m);
  check.Positive("max_accel_m_s2", max_accel_m_s2);
  check.Positive("max_yaw_accel_rad_s2", max_yaw_accel_rad_s2);
  check.NonNegative("kp_xy", kp_xy);
  check.NonNegative("kd_xy", kd_xy);
  check.NonNegative("kp_z", kp_z);
  check.NonNegative("kd_z", kd_z);
  check.NonNegative("kp_tilt", kp_tilt);
  check.NonNegative("kd_tilt", kd_tilt);
  check.NonNegative("kp_yaw", kp_yaw);
  check.NonNegative("kd_yaw", kd_yaw);
  check.NonNegative("swing_kp", swing_kp);
  check.NonNegative("swing_kd", swing_kd);
  check.NonNegative("stance_kd", stance_kd);
  check.Positive("friction", friction);
  for (const auto& [name, v] : hold)
    if (!std::isfinite(v)) check.Fail("hold." + name, "expected a finite ctrl value");
  check.Positive("rate_hz", rate_hz);
}

TrotGait::TrotGait(TrotGaitParams params, ControllerContext context)
    : Controller(std::move(context)), params_(std::move(params)) {
  params_.ValidateOrThrow(this->context());
  for (auto& f : forces_) f.setZero();
  if (!params_.waypoints.empty())
    route_.emplace(params_.waypoints, params_.loop, params_.tolerance_m);
}

std::vector<NameRequirement> TrotGait::RequiredNames() const {
  std::vector<NameRequirement> r;
  r.push_back({ModelObject::kBody, params_.base_body, "base_body"});
  for (int i = 0; i < 4; ++i) {
    const TrotLegConfig& l = params_.legs[i];
    const std::string key = std::string("legs.") + TrotGaitParams::kLegNames[i];
    r.push_back({ModelObject::kJoint, l.hip, key + ".hip"});
    r.push_back({ModelObject::kJoint, l.thigh, key + ".thigh"});
    r.push_back({ModelObject::kJoint, l.calf, key + ".calf"});
    r.push_back({ModelObject::kSite, l.foot, key + ".foot"});
    for (int k = 0; k < 3; ++k)
      r.push_back(
          {ModelObject::kActuator, l.actuators[k], key + ".actuators[" + std::to_string(k) + "]"});
  }
  for (const auto& [name, v] : params_.hold)
    r.push_back({ModelObject::kActuator, name, "hold." + name});
  return r;
}

void TrotGait::OnInitialize(const ModelInfo& model, const std::vector<int>& ids) {
  const ControllerContext& c = context();
  auto fail = [&](const std::string& key, const std::string& problem) {
    throw ConfigError(c.file, c.line, c.key.empty() ? key : c.key + "." + key, problem);
  };
  if (model.body_X_PB.size() != model.body_names.size() ||
      model.body_mass.size() != model.body_names.size() ||
      model.site_X_BS.size() != model.site_names.size())
    fail("base_body",
         "the model information lacks body frames or masses; expected a model "
         "loaded by the simulation");
  base_ = ids[0];
  size_t k = 1;
  for (int i = 0; i < 4; ++i) {
    const TrotLegConfig& cfg = params_.legs[i];
    const std::string key = std::string("legs.") + TrotGaitParams::kLegNames[i];
    Leg& leg = legs_[i];
    std::array<int, 3> joint{};
    for (int j = 0; j < 3; ++j) {
      joint[j] = ids[k++];
      const JointInfo& ji = model.joints[joint[j]];
      if (ji.type != JointInfo::Type::kHinge)
        fail(key, "joint '" + ji.name + "' is not a hinge; expected hinge joints");
      leg.qpos[j] = ji.qpos_adr;
      leg.dof[j] = ji.dof_adr;
      const double s = cfg.signs[j], o = cfg.offsets_rad[j];
      if (ji.limited) {
        const double a = s * ji.range[0] + o, b = s * ji.range[1] + o;
        leg.q_lo[j] = std::min(a, b);
        leg.q_hi[j] = std::max(a, b);
      } else {
        leg.q_lo[j] = -kGaitInf;
        leg.q_hi[j] = kGaitInf;
      }
    }
    const int foot_site = ids[k++];
    for (int j = 0; j < 3; ++j) {
      const int a = ids[k++];
      const ActuatorInfo& ai = model.actuators[a];
      if (ai.joint != joint[j])
        fail(key + ".actuators[" + std::to_string(j) + "]",
             "actuator '" + ai.name + "' does not drive joint '" + model.joints[joint[j]].name +
                 "'; expected a motor or position/velocity servo on that joint");
      // torques go through the actuator's own force law (control/actuator_drive.h); an
      // actuator whose force cannot be set is refused rather than misread
      if (const auto problem = EffortDriveProblem(ai))
        fail(key + ".actuators[" + std::to_string(j) + "]", *problem);
      leg.act[j] = a;
      leg.actuator[j] = ai;
    }
    // geometry from the rest frames
    const int hip_b = model.joints[joint[0]].body, thigh_b = model.joints[joint[1]].body,
              calf_b = model.joints[joint[2]].body;
    const auto X_base_hip = RestFrame(model, base_, hip_b);
    const auto X_hip_thigh = RestFrame(model, hip_b, thigh_b);
    const auto X_thigh_calf = RestFrame(model, thigh_b, calf_b);
    const int site_b = model.site_body[foot_site];
    const auto X_calf_site = RestFrame(model, calf_b, site_b);
    if (!X_base_hip || !X_hip_thigh || !X_thigh_calf || hip_b == thigh_b || thigh_b == calf_b)
      fail(key,
           "the hip, thigh and calf joints must move a chain of bodies below base_body "
           "(hip body, its descendant thigh body, its descendant calf body)");
    if (!X_calf_site)
      fail(key + ".foot", "site '" + cfg.foot + "' is not on the calf body or below it");
    const Eigen::Vector3d t_thigh = X_hip_thigh->translation();
    hip_B_[i] =
        X_base_hip->translation() + X_base_hip->linear() * Eigen::Vector3d(t_thigh.x(), 0, 0);
    const double l1 = std::copysign(std::hypot(t_thigh.y(), t_thigh.z()), t_thigh.y());
    leg.calf_body = calf_b;
    leg.foot_C = (*X_calf_site * model.site_X_BS[foot_site]).translation();
    geometry_[i] = LegGeometry{l1, X_thigh_calf->translation().norm(), leg.foot_C.norm()};
    if (geometry_[i].thigh_m <= 0 || geometry_[i].calf_m <= 0)
      fail(key,
           "zero thigh or calf length; expected the calf body and the foot site away "
           "from the thigh and calf joint axes");
    // start-up check of the signs: each joint's axis in the base frame at the model's rest
    // configuration (from the model) against the canonical axis times its sign (hip about +x,
    // thigh and calf about +y turned by the abduction angle); opposite directions mean the
    // joint turns the other way, so the legs would push the wrong way
    const std::array<Pose, 3> X_base_joint = {*X_base_hip, *X_base_hip * *X_hip_thigh,
                                              *X_base_hip * *X_hip_thigh * *X_thigh_calf};
    const double q_abduction = cfg.signs[0] * model.joints[joint[0]].qpos0 + cfg.offsets_rad[0];
    const Eigen::Vector3d canonical_pitch =
        Eigen::AngleAxisd(q_abduction, Eigen::Vector3d::UnitX()) * Eigen::Vector3d::UnitY();
    const std::array<Eigen::Vector3d, 3> canonical = {Eigen::Vector3d::UnitX(), canonical_pitch,
                                                      canonical_pitch};
    std::array<double, 3> suggested = cfg.signs;
    std::string inverted;
    for (int j = 0; j < 3; ++j) {
      const JointInfo& ji = model.joints[joint[j]];
      const Eigen::Vector3d axis = X_base_joint[j].linear() * ji.axis_B.normalized();
      if (axis.dot(cfg.signs[j] * canonical[j]) > -0.5) continue;
      suggested[j] = -cfg.signs[j];
      inverted += (inverted.empty() ? "'" : ", '") + ji.name + "'";
    }
    if (!inverted.empty()) {
      const auto list = [](const std::array<double, 3>& v) {
        return "[" + std::to_string(static_cast<int>(v[0])) + ", " +
               std::to_string(static_cast<int>(v[1])) + ", " +
               std::to_string(static_cast<int>(v[2])) + "]";
      };
      Warn(key + ": joint(s) " + inverted +
           " move the foot opposite to trot_gait's leg convention at the model's rest pose "
           "(hip abduction about +x, thigh and calf about +y, docs/robots/quadruped.md); the "
           "legs will push the wrong way: set " +
           key + ".signs: " + list(suggested) + " (now " + list(cfg.signs) +
           "), and offsets_rad if their zero differs");
    }
  }
  hold_.clear();
  for (const auto& [name, v] : params_.hold) hold_.emplace_back(ids[k++], v);

  // mass properties of the base subtree (rest configuration for the inertia)
  bodies_.clear();
  body_mass_.clear();
  body_com_B_.clear();
  mass_ = 0;
  Eigen::Vector3d com0 = Eigen::Vector3d::Zero();
  std::vector<Pose> X_base_b;
  for (int b = 1; b < static_cast<int>(model.body_names.size()); ++b) {
    const auto X = RestFrame(model, base_, b);
    if (!X || model.body_mass[b] <= 0) continue;
    bodies_.push_back(b);
    body_mass_.push_back(model.body_mass[b]);
    body_com_B_.push_back(model.body_X_BI[b].translation());
    X_base_b.push_back(*X);
    mass_ += model.body_mass[b];
    com0 += model.body_mass[b] * (*X * model.body_X_BI[b].translation());
  }
  if (mass_ <= 0) fail("base_body", "the robot has no mass; expected bodies with mass");
  com0 /= mass_;
  inertia_B_.setZero();
  for (size_t i = 0; i < bodies_.size(); ++i) {
    const int b = bodies_[i];
    const Eigen::Matrix3d R = X_base_b[i].linear() * model.body_X_BI[b].linear();
    const Eigen::Vector3d r = X_base_b[i] * body_com_B_[i] - com0;
    inertia_B_ +=
        R * model.body_inertia[b].asDiagonal() * R.transpose() +
        body_mass_[i] * (r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose());
  }
  double reach = 0;
  for (const auto& g : geometry_) reach += (g.thigh_m + g.calf_m) / 4;
  leg_length_ = reach;
  step_limit_ = params_.max_step_m.value_or(0.4 * reach);
  limits_.mu = params_.friction;
  limits_.min_normal_n = 0.01 * mass_ * kGravity;
  limits_.max_normal_n = 2.0 * mass_ * kGravity;
  Reset();
}

TrotCommand TrotGait::ScriptedCommand(double t) const {
  TrotCommand cmd;
  for (const auto& tc : params_.commands) {
    if (tc.t_sec > t + 1e-9) break;
    cmd = tc.command;
  }
  return cmd;
}

void TrotGait::FirstUpdate(const ControlInput& in, const Eigen::Vector3d& com,
                           const std::array<Eigen::Vector3d, 4>& feet) {
  for (int i = 0; i < 4; ++i) {
    legs_[i].p_ground = feet[i];
    legs_[i].p_lift = feet[i];
    legs_[i].in_swing = false;
  }
  const Pose X = in.X_WB(base_);
  // start-pose check: in the canonical convention a standing leg has its foot below the hip
  // and its knee bent backwards (q_calf < 0); otherwise a sign or offset is wrong, or the knee
  // bends forwards, which trot_gait's inverse kinematics (knee backwards) does not produce
  const auto qpos = in.qpos();
  for (int i = 0; i < 4; ++i) {
    const TrotLegConfig& cfg = params_.legs[i];
    const double q_calf = cfg.signs[2] * qpos[legs_[i].qpos[2]] + cfg.offsets_rad[2];
    const Eigen::Vector3d foot_B = X.inverse() * feet[i];
    const double below = hip_B_[i].z() - foot_B.z();
    const double reach = geometry_[i].thigh_m + geometry_[i].calf_m;
    const std::string key = std::string("legs.") + TrotGaitParams::kLegNames[i];
    if (q_calf > 0.05) {
      Warn(key + ": in the start pose the knee '" + cfg.calf + "' is at " + std::to_string(q_calf) +
           " rad in trot_gait's convention, i.e. bent forwards; trot_gait bends knees "
           "backwards (calf angle < 0): if the joint turns the other way set " +
           key +
           ".signs[2] (and offsets_rad[2] for another zero); a leg whose knee really bends "
           "forwards is not supported and will stumble");
    } else if (below < 0.25 * reach) {
      Warn(key + ": in the start pose the foot '" + cfg.foot + "' is " + std::to_string(below) +
           " m below the hip (expected about " + std::to_string(0.5 * reach) +
           " m or more for a "
           "standing leg of reach " +
           std::to_string(reach) +
           " m): check the leg's signs and offsets_rad, and the start pose (initial_keyframe)");
    }
  }
  psi_ref_ = std::atan2(X.linear()(1, 0), X.linear()(0, 0));
  p_ref_ = com.head<2>();
  reference_ = TrotCommand{};
  last_t_ = in.time_sec();
  started_ = true;
}

void TrotGait::Reset() {
  override_.reset();
  route_.reset();
  if (!params_.waypoints.empty())
    route_.emplace(params_.waypoints, params_.loop, params_.tolerance_m);
  command_ = TrotCommand{};
  reference_ = TrotCommand{};
  started_ = false;
  last_t_ = 0;
  h_ref_ = 0;
  k_raibert_ = 0;
  psi_ref_ = 0;
  p_ref_.setZero();
  plane_.setZero();
  stance_ = {true, true, true, true};
  for (auto& f : forces_) f.setZero();
  tracking_ = {NAN, NAN, NAN};
  for (Leg& leg : legs_) {
    leg.p_lift.setZero();
    leg.p_ground.setZero();
    leg.in_swing = false;
  }
}

void TrotGait::SetWaypoints(std::vector<Eigen::Vector2d> waypoints, bool loop) {
  if (waypoints.empty()) throw Error(label() + ": empty waypoint list; expected at least 1");
  for (const auto& w : waypoints)
    if (!w.allFinite()) throw Error(label() + ": non-finite waypoint coordinate");
  route_.emplace(std::move(waypoints), loop, params_.tolerance_m);
  override_.reset();
}

void TrotGait::Compute(const ControlInput& in, std::span<double> ctrl) {
  const double t = in.time_sec();
  const Pose X_WB = in.X_WB(base_);
  const Eigen::Matrix3d R = X_WB.linear();
  const Eigen::Vector3d p = X_WB.translation();
  const Twist V = in.V_WB(base_);
  const Eigen::Vector3d w = V.head<3>(), v_base = V.tail<3>();
  const auto qpos = in.qpos();
  const auto qvel = in.qvel();
  const auto bias = in.qfrc_bias();

  // centre of mass and its velocity (rigid-body approximation)
  Eigen::Vector3d com = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < bodies_.size(); ++i)
    com += body_mass_[i] * (in.X_WB(bodies_[i]) * body_com_B_[i]);
  com /= mass_;
  const Eigen::Vector3d v_com = v_base + w.cross(com - p);

  std::array<Eigen::Vector3d, 4> feet;
  for (int i = 0; i < 4; ++i) feet[i] = in.X_WB(legs_[i].calf_body) * legs_[i].foot_C;
  if (!started_) FirstUpdate(in, com, feet);
  const double dt = std::max(0.0, t - last_t_);
  last_t_ = t;

  // 1. command (programmatic > waypoints > script) and references
  if (override_) {
    command_ = *override_;
  } else {
    if (route_) route_->Advance(p.head<2>());
    if (route_ && !route_->finished()) {
      const UnicycleCommand u = PurePursuit(
          X_WB, route_->target(), {params_.speed_m_s, params_.max_yaw_rate_deg_s * M_PI / 180.0});
      command_ = TrotCommand{u.v_m_s, 0.0, u.yaw_rate};
    } else {
      command_ = ScriptedCommand(t);
    }
  }
  auto slew = [dt](double from, double to, double rate) {
    return from + std::clamp(to - from, -rate * dt, rate * dt);
  };
  reference_.vx = slew(reference_.vx, command_.vx, params_.max_accel_m_s2);
  reference_.vy = slew(reference_.vy, command_.vy, params_.max_accel_m_s2);
  reference_.yaw_rate = slew(reference_.yaw_rate, command_.yaw_rate, params_.max_yaw_accel_rad_s2);
  const double psi = std::atan2(R(1, 0), R(0, 0));
  psi_ref_ = psi + std::clamp(GaitWrapAngle(psi_ref_ + reference_.yaw_rate * dt - psi),
                              -kMaxHeadingLead, kMaxHeadingLead);
  const double cp = std::cos(psi), sp = std::sin(psi);
  const Eigen::Vector2d v_ref_xy(cp * reference_.vx - sp * reference_.vy,
                                 sp * reference_.vx + cp * reference_.vy);
  tracking_ = {reference_.vx - (cp * v_com.x() + sp * v_com.y()),
               reference_.vy - (-sp * v_com.x() + cp * v_com.y()), reference_.yaw_rate - w.z()};
  p_ref_ += v_ref_xy * dt;
  Eigen::Vector2d lead = p_ref_ - com.head<2>();
  if (lead.norm() > kMaxPositionLead) lead *= kMaxPositionLead / lead.norm();
  p_ref_ = com.head<2>() + lead;

  // 2. gait schedule
  const double T = params_.period_sec, D = params_.duty;
  const double T_st = D * T, T_sw = (1 - D) * T;
  const double phase = t / T - std::floor(t / T);
  std::array<double, 4> s_swing{};
  for (int i = 0; i < 4; ++i) {
    double lp = phase - kPhaseOffset[i];
    if (lp < 0) lp += 1.0;
    stance_[i] = lp < D;
    s_swing[i] = stance_[i] ? 0.0 : (lp - D) / (1 - D);
    Leg& leg = legs_[i];
    if (stance_[i]) {
      leg.in_swing = false;
      leg.p_ground = feet[i];
    } else if (!leg.in_swing) {
      leg.in_swing = true;
      leg.p_lift = feet[i];
    }
  }

  // ground plane z = a + b x + c y through the feet's last stance positions (least squares,
  // slopes lightly regularised so that collinear feet still give a plane)
  {
    Eigen::Matrix3d N = Eigen::Matrix3d::Zero();
    Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
    for (const Leg& leg : legs_) {
      const Eigen::Vector3d row(1, leg.p_ground.x() - com.x(), leg.p_ground.y() - com.y());
      N += row * row.transpose();
      rhs += row * leg.p_ground.z();
    }
    N(1, 1) += 1e-4;
    N(2, 2) += 1e-4;
    const Eigen::Vector3d sol = N.inverse() * rhs;  // about the COM's xy
    const double b = std::clamp(sol[1], -0.6, 0.6), c = std::clamp(sol[2], -0.6, 0.6);
    plane_ = Eigen::Vector3d(sol[0] - b * com.x() - c * com.y(), b, c);
  }
  auto ground_z = [&](double x, double y) { return plane_[0] + plane_[1] * x + plane_[2] * y; };
  const Eigen::Vector3d normal = Eigen::Vector3d(-plane_[1], -plane_[2], 1).normalized();
  const double h = com.z() - ground_z(com.x(), com.y());
  // a robot that starts crouched or lying still gets a sensible target
  if (h_ref_ <= 0) h_ref_ = params_.body_height_m.value_or(std::max(h, 0.3 * leg_length_));
  if (k_raibert_ <= 0) k_raibert_ = params_.raibert_gain.value_or(std::sqrt(h_ref_ / kGravity));

  // 3. stance: desired wrench on the COM, distributed over the stance feet
  const double v_ref_z = plane_[1] * v_ref_xy.x() + plane_[2] * v_ref_xy.y();
  Eigen::Vector3d acc;
  acc.head<2>() =
      params_.kp_xy * (p_ref_ - com.head<2>()) + params_.kd_xy * (v_ref_xy - v_com.head<2>());
  acc.z() = params_.kp_z * (h_ref_ - h) + params_.kd_z * (v_ref_z - v_com.z());
  Eigen::Matrix3d R_ref;
  {
    const Eigen::Vector3d x_h(std::cos(psi_ref_), std::sin(psi_ref_), 0);
    const Eigen::Vector3d x_ref = (x_h - x_h.dot(normal) * normal).normalized();
    R_ref.col(0) = x_ref;
    R_ref.col(1) = normal.cross(x_ref);
    R_ref.col(2) = normal;
  }
  // attitude error on SO(3) in the base frame (T. Lee, M. Leok, N. H. McClamroch, "Geometric
  // tracking control of a quadrotor UAV on SE(3)", CDC 2010): e = 1/2 (R^T R_ref - R_ref^T R)^v,
  // the rotation vector from R to R_ref for small errors
  const Eigen::Matrix3d E = R.transpose() * R_ref;
  const Eigen::Vector3d e_B =
      0.5 * Eigen::Vector3d(E(2, 1) - E(1, 2), E(0, 2) - E(2, 0), E(1, 0) - E(0, 1));
  const Eigen::Vector3d w_err_B = R.transpose() * (Eigen::Vector3d(0, 0, reference_.yaw_rate) - w);
  const Eigen::Vector3d alpha_B(params_.kp_tilt * e_B.x() + params_.kd_tilt * w_err_B.x(),
                                params_.kp_tilt * e_B.y() + params_.kd_tilt * w_err_B.y(),
                                params_.kp_yaw * e_B.z() + params_.kd_yaw * w_err_B.z());
  Eigen::Matrix<double, 6, 1> wrench;
  wrench.head<3>() = mass_ * (acc + Eigen::Vector3d(0, 0, kGravity));
  wrench.tail<3>() = R * (inertia_B_ * alpha_B);
  std::array<Eigen::Vector3d, 4> r;
  for (int i = 0; i < 4; ++i) r[i] = feet[i] - com;
  DistributeStanceForces(r, stance_, wrench, normal, limits_, &forces_);

  auto write = [&](const Leg& leg, int j, double tau) {
    ctrl[leg.act[j]] = CtrlForEffort(leg.actuator[j], tau, qpos[leg.qpos[j]], qvel[leg.dof[j]]);
  };
  for (int i = 0; i < 4; ++i) {
    Leg& leg = legs_[i];
    const TrotLegConfig& cfg = params_.legs[i];
    if (stance_[i]) {
      // tau = S J^T R^T (-f): J the leg's analytic Jacobian in the base frame at the
      // measured angles, S the sign map
      Eigen::Vector3d q_can;
      for (int j = 0; j < 3; ++j) q_can[j] = cfg.signs[j] * qpos[leg.qpos[j]] + cfg.offsets_rad[j];
      const Eigen::Vector3d tau_can =
          LegJacobian(geometry_[i], q_can).transpose() * (R.transpose() * -forces_[i]);
      for (int j = 0; j < 3; ++j)
        write(leg, j, cfg.signs[j] * tau_can[j] - params_.stance_kd * qvel[leg.dof[j]]);
      continue;
    }
    // 4. swing: Raibert touch-down point, cycloid, IK and joint PD
    const double t_rem = (1 - s_swing[i]) * T_sw;
    const Eigen::Vector3d nominal_B = hip_B_[i] + Eigen::Vector3d(0, geometry_[i].abduction_m, 0);
    const Eigen::Vector3d nominal_W = p + R * nominal_B;
    const Eigen::Vector2d arm = (nominal_W - com).head<2>();
    const Eigen::Vector2d v_nom_ref =
        v_ref_xy + reference_.yaw_rate * Eigen::Vector2d(-arm.y(), arm.x());
    const Eigen::Vector2d hip_td = nominal_W.head<2>() + v_nom_ref * t_rem;
    Eigen::Vector2d step =
        v_ref_xy * (T_st / 2) + k_raibert_ * (v_com.head<2>() - v_ref_xy) +
        (h_ref_ / (2 * kGravity)) * reference_.yaw_rate * Eigen::Vector2d(v_com.y(), -v_com.x());
    if (step.norm() > step_limit_) step *= step_limit_ / step.norm();
    Eigen::Vector3d p_td;
    p_td.head<2>() = hip_td + step;
    p_td.z() = ground_z(p_td.x(), p_td.y()) - kTouchdownDepth;
    const SwingSample target =
        CycloidSwing(leg.p_lift, p_td, params_.swing_height_m, s_swing[i], T_sw);
    const Eigen::Vector3d p_H = R.transpose() * (target.p - p) - hip_B_[i];
    const Eigen::Vector3d v_H = R.transpose() * (target.v - v_base - w.cross(target.p - p));
    Eigen::Vector3d q_can;
    LegInverseKinematics(geometry_[i], p_H, &q_can);
    const Eigen::Matrix3d J = LegJacobian(geometry_[i], q_can);
    const Eigen::Matrix3d JtJ = J.transpose() * J + 1e-4 * Eigen::Matrix3d::Identity();
    const Eigen::Vector3d qd_can = JtJ.inverse() * (J.transpose() * v_H);
    for (int j = 0; j < 3; ++j) {
      const double q_des_can = std::clamp(q_can[j], leg.q_lo[j], leg.q_hi[j]);
      const double s = cfg.signs[j];
      const double q_des = s * (q_des_can - cfg.offsets_rad[j]);
      const double qd_des = s * qd_can[j];
      const double tau = params_.swing_kp * (q_des - qpos[leg.qpos[j]]) +
                         params_.swing_kd * (qd_des - qvel[leg.dof[j]]) +
                         (bias.empty() ? 0.0 : bias[leg.dof[j]]);
      write(leg, j, tau);
    }
  }
  for (const auto& [a, v] : hold_) ctrl[a] = v;
}

}  // namespace penumbra
