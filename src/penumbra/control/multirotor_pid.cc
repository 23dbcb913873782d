#include "penumbra/control/multirotor_pid.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "penumbra/config/config_value.h"
#include "penumbra/control/param_limits.h"
#include "penumbra/control/param_mapping.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

constexpr double kPidDegToRad = M_PI / 180.0;
// velocity integrator: input clipped to this error (m/s), and frozen while the thrust axis is
// more than this far from its setpoint (rad), so an upset or a large step does not wind it up
constexpr double kIntegratorErrorClip = 0.5;
const double kCosIntegratorMaxTiltError = std::cos(20 * kPidDegToRad);

double PidWrapAngle(double a) {
  a = std::remainder(a, 2 * M_PI);  // in [-pi, pi]
  return a <= -M_PI ? a + 2 * M_PI : a;
}

std::string PidFmt(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

using param::Repr;

std::string PidRangeText(double min, double max, bool min_exclusive) {
  return std::string(min_exclusive ? "> " : ">= ") + PidFmt(min) +
         (std::isinf(max) ? "" : " and <= " + PidFmt(max));
}

// readers for values inside structured parameters (commands, rotor list); errors name the
// full key path through ControllerParams::Fail
double NodeNumber(const ControllerParams& p, const ConfigValue& n, const std::string& key,
                  double min, double max, bool min_exclusive = false) {
  double v = 0;
  const bool ok = n.ToDoubleLoose(&v);
  const std::string range = PidRangeText(min, max, min_exclusive);
  if (!ok || !std::isfinite(v)) p.Fail(key, "got " + Repr(n) + "; expected a number " + range);
  if (v < min || (min_exclusive && v == min) || v > max)
    p.Fail(key, "got " + PidFmt(v) + "; expected a number " + range);
  return v;
}

Eigen::Vector3d NodeVec3(const ControllerParams& p, const ConfigValue& n, const std::string& key,
                         const char* what, double bound) {
  if (!n.IsSequence() || n.size() != 3) p.Fail(key, "got " + Repr(n) + "; expected " + what);
  Eigen::Vector3d v;
  for (int k = 0; k < 3; ++k)
    v[k] = NodeNumber(p, n[k], key + "[" + std::to_string(k) + "]", -bound, bound);
  return v;
}

std::string NodeName(const ControllerParams& p, const ConfigValue& n, const std::string& key) {
  if (!n.IsScalar() || n.Scalar().empty()) p.Fail(key, "got " + Repr(n) + "; expected a name");
  return n.Scalar();
}

bool NodeBool(const ControllerParams& p, const ConfigValue& n, const std::string& key) {
  bool v = false;
  if (n.ToBoolLoose(&v)) return v;
  p.Fail(key, "got " + Repr(n) + "; expected true or false");
}

// the keys each mode accepts besides t and mode
std::vector<std::string> ModeKeys(MultirotorCommand::Mode mode) {
  using M = MultirotorCommand::Mode;
  switch (mode) {
    case M::kIdle:
      return {};
    case M::kTakeoff:
      return {"altitude_m", "speed_m_s", "yaw_deg"};
    case M::kHover:
      return {"position", "speed_m_s", "yaw_deg"};
    case M::kWaypoints:
      return {"waypoints", "speed_m_s", "yaw_deg", "face_path"};
    case M::kVelocity:
      return {"velocity_m_s", "yaw_rate_deg_s", "frame"};
    case M::kLand:
      return {};
  }
  return {};
}

TimedMultirotorCommand ParseCommand(const ControllerParams& p, const ConfigValue& n,
                                    const std::string& key) {
  using M = MultirotorCommand::Mode;
  if (!n.IsMap())
    p.Fail(key, "got " + Repr(n) +
                    "; expected a mapping such as {t: 0, mode: takeoff, altitude_m: 1.5}");
  TimedMultirotorCommand tc;
  MultirotorCommand& c = tc.command;
  if (!n["t"]) p.Fail(key + ".t", "missing; expected the start time in s (sim time, >= 0)");
  tc.t_sec = NodeNumber(p, n["t"], key + ".t", 0, kMaxParamTimeSec);
  if (!n["mode"])
    p.Fail(key + ".mode",
           "missing; expected one of idle, takeoff, hover, waypoints, velocity, land");
  const std::string mode = NodeName(p, n["mode"], key + ".mode");
  bool known = false;
  for (M m : {M::kIdle, M::kTakeoff, M::kHover, M::kWaypoints, M::kVelocity, M::kLand})
    if (mode == MultirotorCommand::ModeName(m)) {
      c.mode = m;
      known = true;
    }
  if (!known)
    p.Fail(key + ".mode",
           "got '" + mode + "'; expected one of idle, takeoff, hover, waypoints, velocity, land");

  const std::vector<std::string> allowed = ModeKeys(c.mode);
  for (const auto& kv : n.pairs()) {
    const std::string k = kv.first.Scalar();
    if (k == "t" || k == "mode" || std::find(allowed.begin(), allowed.end(), k) != allowed.end())
      continue;
    std::string list = "t, mode";
    for (const auto& a : allowed) list += ", " + a;
    p.Fail(key + "." + k, "unknown key for mode " + mode + "; expected only: " + list);
  }

  const std::string speed_key = key + ".speed_m_s";
  if (n["speed_m_s"])
    c.speed_m_s = NodeNumber(p, n["speed_m_s"], speed_key, 0, kMaxParamSpeedMS, true);
  if (n["yaw_deg"])
    c.yaw_deg =
        NodeNumber(p, n["yaw_deg"], key + ".yaw_deg", -kMaxParamAngleDeg, kMaxParamAngleDeg);
  switch (c.mode) {
    case M::kIdle:
    case M::kLand:
      break;
    case M::kTakeoff:
      if (!n["altitude_m"])
        p.Fail(key + ".altitude_m", "missing; expected the target altitude (world z, m)");
      c.altitude_m = NodeNumber(p, n["altitude_m"], key + ".altitude_m", -kMaxParamPositionM,
                                kMaxParamPositionM);
      break;
    case M::kHover:
      if (n["position"])
        c.position = NodeVec3(p, n["position"], key + ".position", "[x, y, z] (world, m)",
                              kMaxParamPositionM);
      break;
    case M::kWaypoints: {
      const ConfigValue w = n["waypoints"];
      const char* expected = "a list of at least 1 [x, y, z] point (world, m)";
      if (!w) p.Fail(key + ".waypoints", std::string("missing; expected ") + expected);
      if (!w.IsSequence() || w.size() == 0)
        p.Fail(key + ".waypoints", "got " + Repr(w) + "; expected " + expected);
      for (size_t i = 0; i < w.size(); ++i)
        c.waypoints.push_back(NodeVec3(p, w[i], key + ".waypoints[" + std::to_string(i) + "]",
                                       "[x, y, z] (world, m)", kMaxParamPositionM));
      if (n["face_path"]) c.face_path = NodeBool(p, n["face_path"], key + ".face_path");
      break;
    }
    case M::kVelocity:
      if (n["velocity_m_s"])
        c.velocity_m_s = NodeVec3(p, n["velocity_m_s"], key + ".velocity_m_s", "[vx, vy, vz] (m/s)",
                                  kMaxParamSpeedMS);
      if (n["yaw_rate_deg_s"])
        c.yaw_rate_deg_s = NodeNumber(p, n["yaw_rate_deg_s"], key + ".yaw_rate_deg_s",
                                      -kMaxParamAngularSpeedDegS, kMaxParamAngularSpeedDegS);
      if (n["frame"]) {
        const std::string f = NodeName(p, n["frame"], key + ".frame");
        if (f == "world") {
          c.frame = MultirotorCommand::Frame::kWorld;
        } else if (f == "heading") {
          c.frame = MultirotorCommand::Frame::kHeading;
        } else {
          p.Fail(key + ".frame", "got '" + f + "'; expected world or heading");
        }
      }
      break;
  }
  return tc;
}

// first-order low-pass coefficient for a sample interval dt and a cutoff frequency
double LowPassAlpha(double dt, double cutoff_hz) {
  const double tau = 1.0 / (2 * M_PI * cutoff_hz);
  return dt / (dt + tau);
}

}  // namespace

const char* MultirotorCommand::ModeName(Mode mode) {
  switch (mode) {
    case Mode::kIdle:
      return "idle";
    case Mode::kTakeoff:
      return "takeoff";
    case Mode::kHover:
      return "hover";
    case Mode::kWaypoints:
      return "waypoints";
    case Mode::kVelocity:
      return "velocity";
    case Mode::kLand:
      return "land";
  }
  return "unknown";
}

void MultirotorCommand::ValidateOrThrow(const ControllerContext& c, const std::string& key) const {
  auto fail = [&](const std::string& sub, const std::string& problem) {
    const std::string k = key + "." + sub;
    throw ConfigError(c.file, c.line, c.key.empty() ? k : c.key + "." + k, problem);
  };
  if (!(std::isfinite(altitude_m))) fail("altitude_m", "not finite; expected a number (m)");
  if (position && !position->allFinite()) fail("position", "not finite; expected [x, y, z] (m)");
  for (const auto& w : waypoints)
    if (!w.allFinite()) fail("waypoints", "non-finite coordinate; expected finite numbers (m)");
  if (mode == Mode::kWaypoints && waypoints.empty())
    fail("waypoints", "empty; expected at least 1 [x, y, z] point");
  if (!(std::isfinite(speed_m_s) && speed_m_s > 0))
    fail("speed_m_s", "got " + PidFmt(speed_m_s) + "; expected a number > 0");
  if (yaw_deg && !std::isfinite(*yaw_deg)) fail("yaw_deg", "not finite; expected degrees");
  if (!velocity_m_s.allFinite()) fail("velocity_m_s", "not finite; expected [vx, vy, vz] (m/s)");
  if (!std::isfinite(yaw_rate_deg_s)) fail("yaw_rate_deg_s", "not finite; expected deg/s");
}

MultirotorPidParams MultirotorPidParams::Parse(ControllerParams& p,
                                               const std::string& name_prefix) {
  MultirotorPidParams m;
  m.base_body = name_prefix + p.String("base_body");

  const ConfigValue* rotors = p.Raw("rotor_actuators");
  const char* rotors_expected =
      "a list of at least 4 rotor actuator names, e.g. [thrust_fr, thrust_rl, thrust_fl, "
      "thrust_rr]";
  if (!rotors) p.Fail("rotor_actuators", std::string("missing; expected ") + rotors_expected);
  if (!rotors->IsSequence() || rotors->size() < 4)
    p.Fail("rotor_actuators", "got " + Repr(*rotors) + "; expected " + rotors_expected);
  for (size_t i = 0; i < rotors->size(); ++i) {
    const std::string key = "rotor_actuators[" + std::to_string(i) + "]";
    const std::string name = name_prefix + NodeName(p, (*rotors)[i], key);
    if (std::find(m.rotor_actuators.begin(), m.rotor_actuators.end(), name) !=
        m.rotor_actuators.end())
      p.Fail(key, "actuator '" + name + "' listed twice; expected each rotor once");
    m.rotor_actuators.push_back(name);
  }
  if (m.rotor_actuators.size() > MultirotorMixer::kMaxRotors)
    p.Fail("rotor_actuators", "got " + std::to_string(m.rotor_actuators.size()) +
                                  " rotors; expected at most " +
                                  std::to_string(MultirotorMixer::kMaxRotors));

  auto pos = [&](const char* key, double fallback, double max = kMaxParamGain) {
    return p.Number(key, fallback, 0, max, true);
  };
  auto nonneg = [&](const char* key, double fallback, double max = kMaxParamGain) {
    return p.Number(key, fallback, 0, max);
  };
  m.rate_hz = pos("rate_hz", m.rate_hz, kMaxParamRateHz);
  m.gravity_m_s2 = pos("gravity_m_s2", m.gravity_m_s2, kMaxParamAccelerationMS2);
  m.max_speed_xy_m_s = pos("max_speed_xy_m_s", m.max_speed_xy_m_s, kMaxParamSpeedMS);
  m.max_climb_m_s = pos("max_climb_m_s", m.max_climb_m_s, kMaxParamSpeedMS);
  m.max_descent_m_s = pos("max_descent_m_s", m.max_descent_m_s, kMaxParamSpeedMS);
  m.max_accel_m_s2 = pos("max_accel_m_s2", m.max_accel_m_s2, kMaxParamAccelerationMS2);
  m.max_jerk_m_s3 = pos("max_jerk_m_s3", m.max_jerk_m_s3, kMaxParamJerkMS3);
  m.max_tilt_deg = p.Number("max_tilt_deg", m.max_tilt_deg, 0, 80, true);
  m.max_roll_pitch_rate_deg_s =
      pos("max_roll_pitch_rate_deg_s", m.max_roll_pitch_rate_deg_s, kMaxParamAngularSpeedDegS);
  m.max_yaw_rate_deg_s = pos("max_yaw_rate_deg_s", m.max_yaw_rate_deg_s, kMaxParamAngularSpeedDegS);
  m.yaw_speed_deg_s = pos("yaw_speed_deg_s", m.yaw_speed_deg_s, kMaxParamAngularSpeedDegS);
  m.leash_m = pos("leash_m", m.leash_m, kMaxParamPositionM);
  m.land_speed_m_s = pos("land_speed_m_s", m.land_speed_m_s, kMaxParamSpeedMS);
  m.position_p_xy = pos("position_p_xy", m.position_p_xy);
  m.position_p_z = pos("position_p_z", m.position_p_z);
  m.velocity_p_xy = pos("velocity_p_xy", m.velocity_p_xy);
  m.velocity_i_xy = nonneg("velocity_i_xy", m.velocity_i_xy);
  m.velocity_d_xy = nonneg("velocity_d_xy", m.velocity_d_xy);
  m.velocity_p_z = pos("velocity_p_z", m.velocity_p_z);
  m.velocity_i_z = nonneg("velocity_i_z", m.velocity_i_z);
  m.velocity_d_z = nonneg("velocity_d_z", m.velocity_d_z);
  m.velocity_i_limit_m_s2 =
      nonneg("velocity_i_limit_m_s2", m.velocity_i_limit_m_s2, kMaxParamAccelerationMS2);
  m.attitude_p_roll_pitch = pos("attitude_p_roll_pitch", m.attitude_p_roll_pitch);
  m.attitude_p_yaw = pos("attitude_p_yaw", m.attitude_p_yaw);
  m.rate_p_roll_pitch = pos("rate_p_roll_pitch", m.rate_p_roll_pitch);
  m.rate_i_roll_pitch = nonneg("rate_i_roll_pitch", m.rate_i_roll_pitch);
  m.rate_d_roll_pitch = nonneg("rate_d_roll_pitch", m.rate_d_roll_pitch);
  m.rate_p_yaw = pos("rate_p_yaw", m.rate_p_yaw);
  m.rate_i_yaw = nonneg("rate_i_yaw", m.rate_i_yaw);
  m.rate_d_yaw = nonneg("rate_d_yaw", m.rate_d_yaw);
  m.rate_i_limit_rad_s2 =
      nonneg("rate_i_limit_rad_s2", m.rate_i_limit_rad_s2, kMaxParamAngularAccelerationRadS2);
  m.derivative_cutoff_hz = pos("derivative_cutoff_hz", m.derivative_cutoff_hz, kMaxParamRateHz);

  if (const ConfigValue* cmds = p.Raw("commands")) {
    if (!cmds->IsSequence())
      p.Fail("commands", "got " + Repr(*cmds) +
                             "; expected a list of timed commands, e.g. [{t: 0, mode: takeoff, "
                             "altitude_m: 1.5}]");
    for (size_t i = 0; i < cmds->size(); ++i) {
      const std::string key = "commands[" + std::to_string(i) + "]";
      TimedMultirotorCommand tc = ParseCommand(p, (*cmds)[i], key);
      if (!m.commands.empty() && tc.t_sec < m.commands.back().t_sec)
        p.Fail(key + ".t", "got " + PidFmt(tc.t_sec) + ", before the previous command's t = " +
                               PidFmt(m.commands.back().t_sec) + "; expected non-decreasing times");
      m.commands.push_back(std::move(tc));
    }
  }
  p.CheckNoUnknownKeys();
  return m;
}

void MultirotorPidParams::ValidateOrThrow(const ControllerContext& c) const {
  auto fail = [&](const std::string& key, const std::string& problem) {
    throw ConfigError(c.file, c.line, c.key.empty() ? key : c.key + "." + key, problem);
  };
  auto check = [&](const char* key, double v, bool strictly_positive) {
    if (!std::isfinite(v) || v < 0 || (strictly_positive && v == 0))
      fail(key, "got " + PidFmt(v) + "; expected a number " + (strictly_positive ? "> 0" : ">= 0"));
  };
  if (base_body.empty()) fail("base_body", "missing; expected a body name");
  if (rotor_actuators.size() < 4 ||
      rotor_actuators.size() > static_cast<size_t>(MultirotorMixer::kMaxRotors))
    fail("rotor_actuators", "got " + std::to_string(rotor_actuators.size()) +
                                " rotors; expected 4 to " +
                                std::to_string(MultirotorMixer::kMaxRotors));
  for (size_t i = 0; i < rotor_actuators.size(); ++i) {
    if (rotor_actuators[i].empty())
      fail("rotor_actuators[" + std::to_string(i) + "]", "empty; expected an actuator name");
    for (size_t j = 0; j < i; ++j)
      if (rotor_actuators[i] == rotor_actuators[j])
        fail("rotor_actuators[" + std::to_string(i) + "]",
             "actuator '" + rotor_actuators[i] + "' listed twice; expected each rotor once");
  }
  check("rate_hz", rate_hz, true);
  check("gravity_m_s2", gravity_m_s2, true);
  check("max_speed_xy_m_s", max_speed_xy_m_s, true);
  check("max_climb_m_s", max_climb_m_s, true);
  check("max_descent_m_s", max_descent_m_s, true);
  check("max_accel_m_s2", max_accel_m_s2, true);
  check("max_jerk_m_s3", max_jerk_m_s3, true);
  check("max_tilt_deg", max_tilt_deg, true);
  if (max_tilt_deg > 80) fail("max_tilt_deg", "got " + PidFmt(max_tilt_deg) + "; expected <= 80");
  check("max_roll_pitch_rate_deg_s", max_roll_pitch_rate_deg_s, true);
  check("max_yaw_rate_deg_s", max_yaw_rate_deg_s, true);
  check("yaw_speed_deg_s", yaw_speed_deg_s, true);
  check("leash_m", leash_m, true);
  check("land_speed_m_s", land_speed_m_s, true);
  check("position_p_xy", position_p_xy, true);
  check("position_p_z", position_p_z, true);
  check("velocity_p_xy", velocity_p_xy, true);
  check("velocity_i_xy", velocity_i_xy, false);
  check("velocity_d_xy", velocity_d_xy, false);
  check("velocity_p_z", velocity_p_z, true);
  check("velocity_i_z", velocity_i_z, false);
  check("velocity_d_z", velocity_d_z, false);
  check("velocity_i_limit_m_s2", velocity_i_limit_m_s2, false);
  check("attitude_p_roll_pitch", attitude_p_roll_pitch, true);
  check("attitude_p_yaw", attitude_p_yaw, true);
  check("rate_p_roll_pitch", rate_p_roll_pitch, true);
  check("rate_i_roll_pitch", rate_i_roll_pitch, false);
  check("rate_d_roll_pitch", rate_d_roll_pitch, false);
  check("rate_p_yaw", rate_p_yaw, true);
  check("rate_i_yaw", rate_i_yaw, false);
  check("rate_d_yaw", rate_d_yaw, false);
  check("rate_i_limit_rad_s2", rate_i_limit_rad_s2, false);
  check("derivative_cutoff_hz", derivative_cutoff_hz, true);
  for (size_t i = 0; i < commands.size(); ++i) {
    const std::string key = "commands[" + std::to_string(i) + "]";
    if (!(std::isfinite(commands[i].t_sec) && commands[i].t_sec >= 0))
      fail(key + ".t", "got " + PidFmt(commands[i].t_sec) + "; expected a time >= 0 (s)");
    if (i > 0 && commands[i].t_sec < commands[i - 1].t_sec)
      fail(key + ".t", "before the previous command; expected non-decreasing times");
    commands[i].command.ValidateOrThrow(c, key);
  }
}

MultirotorPid::MultirotorPid(MultirotorPidParams params, ControllerContext context)
    : Controller(std::move(context)), params_(std::move(params)) {
  params_.ValidateOrThrow(this->context());
  tan_max_tilt_ = std::tan(params_.max_tilt_deg * kPidDegToRad);
}

std::vector<NameRequirement> MultirotorPid::RequiredNames() const {
  std::vector<NameRequirement> r = {{ModelObject::kBody, params_.base_body, "base_body"}};
  for (size_t i = 0; i < params_.rotor_actuators.size(); ++i)
    r.push_back({ModelObject::kActuator, params_.rotor_actuators[i],
                 "rotor_actuators[" + std::to_string(i) + "]"});
  return r;
}

void MultirotorPid::OnInitialize(const ModelInfo& model, const std::vector<int>& ids) {
  base_ = ids[0];
  rotors_.assign(ids.begin() + 1, ids.end());
  const ControllerContext& c = context();
  bool has_free_joint = false;
  for (const JointInfo& j : model.joints)
    if (j.body == base_ && j.type == JointInfo::Type::kFree) has_free_joint = true;
  if (!has_free_joint)
    throw ConfigError(c.file, c.line, c.key.empty() ? "base_body" : c.key + ".base_body",
                      "body '" + params_.base_body +
                          "' has no free joint; expected the free-flying airframe body");
  std::vector<std::string> keys;
  for (size_t i = 0; i < rotors_.size(); ++i)
    keys.push_back("rotor_actuators[" + std::to_string(i) + "]");
  airframe_ = BuildMultirotorModel(model, base_, rotors_, keys, c);
  try {
    mixer_ = MultirotorMixer(airframe_.allocation, airframe_.min_thrust_n, airframe_.max_thrust_n);
  } catch (const Error& e) {
    throw ConfigError(
        c.file, c.line, c.key.empty() ? "rotor_actuators" : c.key + ".rotor_actuators",
        std::string(e.what()) + "; expected rotors that can lift and steer the airframe");
  }
  Reset();
}

void MultirotorPid::SetCommand(const MultirotorCommand& command) {
  command.ValidateOrThrow(context(), "command");
  std::lock_guard<std::mutex> lock(pending_mutex_);
  pending_ = command;
  has_pending_.store(true, std::memory_order_release);
}

void MultirotorPid::Reset() {
  {
    std::lock_guard<std::mutex> lock(pending_mutex_);
    has_pending_.store(false, std::memory_order_release);
    pending_ = MultirotorCommand{};
  }
  next_scripted_ = 0;
  mode_ = MultirotorCommand::Mode::kIdle;
  path_ = MultirotorPath();
  path_time_ = 0;
  face_path_ = false;
  v_cmd_.setZero();
  yaw_rate_cmd_ = 0;
  touchdown_sec_ = 0;
  frame_ = MultirotorCommand::Frame::kWorld;
  p_ref_.setZero();
  yaw_ref_ = yaw_target_ = 0;
  started_ = false;
  t_prev_ = 0;
  v_prev_.setZero();
  w_prev_.setZero();
  alpha_dt_ = -1;
  alpha_ = 0;
  heading_yaw_ = std::numeric_limits<double>::quiet_NaN();
  heading_ = Eigen::Vector3d::UnitX();
  last_collective_request_ = 0;
  thrust_.assign(rotors_.size(), 0.0);
  ResetState();
}

void MultirotorPid::ResetState() {
  vel_int_.setZero();
  rate_int_.setZero();
  acc_filt_.setZero();
  wdot_filt_.setZero();
  v_ff_.setZero();
  a_ff_.setZero();
  j_ff_.setZero();
  yaw_rate_ff_ = 0;
  have_prev_ = false;
  xy_limited_ = false;
  tilt_error_large_ = false;
  mix_ = MixResult();
}

void MultirotorPid::ApplyCommand(const MultirotorCommand& cmd, const Eigen::Vector3d& p,
                                 double yaw) {
  using M = MultirotorCommand::Mode;
  const bool was_idle = mode_ == M::kIdle;
  if (was_idle) {
    ResetState();
    p_ref_ = p;
    yaw_ref_ = yaw;
  }
  const Eigen::Vector3d start = p_ref_;
  yaw_target_ = cmd.yaw_deg ? PidWrapAngle(*cmd.yaw_deg * kPidDegToRad) : yaw_ref_;
  face_path_ = false;
  mode_ = cmd.mode;
  path_time_ = 0;
  const double accel = params_.max_accel_m_s2;
  switch (cmd.mode) {
    case M::kIdle:
      path_ = MultirotorPath(start, {}, 1, accel);
      break;
    case M::kTakeoff: {
      const Eigen::Vector3d target(start.x(), start.y(), cmd.altitude_m);
      const double limit =
          target.z() >= start.z() ? params_.max_climb_m_s : params_.max_descent_m_s;
      path_ = MultirotorPath(start, {target}, std::min(cmd.speed_m_s, limit), accel);
      break;
    }
    case M::kHover:
      path_ = MultirotorPath(start, {cmd.position.value_or(start)},
                             std::min(cmd.speed_m_s, params_.max_speed_xy_m_s), accel);
      break;
    case M::kWaypoints:
      path_ = MultirotorPath(start, cmd.waypoints,
                             std::min(cmd.speed_m_s, params_.max_speed_xy_m_s), accel);
      face_path_ = cmd.face_path;
      break;
    case M::kVelocity:
      path_ = MultirotorPath(start, {}, 1, accel);
      v_cmd_ = cmd.velocity_m_s;
      yaw_rate_cmd_ =
          std::clamp(cmd.yaw_rate_deg_s * kPidDegToRad, -params_.max_yaw_rate_deg_s * kPidDegToRad,
                     params_.max_yaw_rate_deg_s * kPidDegToRad);
      frame_ = cmd.frame;
      break;
    case M::kLand:
      path_ = MultirotorPath(start, {}, 1, accel);
      v_cmd_ = Eigen::Vector3d(0, 0, -std::min(params_.land_speed_m_s, params_.max_descent_m_s));
      yaw_rate_cmd_ = 0;
      frame_ = MultirotorCommand::Frame::kWorld;
      touchdown_sec_ = 0;
      break;
  }
}

void MultirotorPid::UpdateReference(double dt, const Eigen::Vector3d& p) {
  using M = MultirotorCommand::Mode;
  if (mode_ == M::kVelocity || mode_ == M::kLand) {
    // velocity command, smoothed, integrated into the position reference
    Eigen::Vector3d target = v_cmd_;
    if (frame_ == MultirotorCommand::Frame::kHeading)
      target.head<2>() = Eigen::Rotation2Dd(yaw_ref_) * v_cmd_.head<2>();
    const double sxy = target.head<2>().norm();
    if (sxy > params_.max_speed_xy_m_s) target.head<2>() *= params_.max_speed_xy_m_s / sxy;
    target.z() = std::clamp(target.z(), -params_.max_descent_m_s, params_.max_climb_m_s);
    // first-order approach (time constant 0.25 s) with acceleration and jerk limits
    Eigen::Vector3d a_des = 4.0 * (target - v_ff_);
    if (a_des.norm() > params_.max_accel_m_s2) a_des *= params_.max_accel_m_s2 / a_des.norm();
    Eigen::Vector3d da = a_des - a_ff_;
    const double max_da = params_.max_jerk_m_s3 * dt;
    if (da.norm() > max_da) da *= max_da / da.norm();
    a_ff_ += da;
    j_ff_ = da / dt;
    v_ff_ += a_ff_ * dt;
    p_ref_ += v_ff_ * dt;
    const Eigen::Vector3d lead = p_ref_ - p;
    if (lead.norm() > params_.leash_m) p_ref_ = p + lead * (params_.leash_m / lead.norm());
    yaw_rate_ff_ = yaw_rate_cmd_;
    yaw_ref_ = PidWrapAngle(yaw_ref_ + yaw_rate_cmd_ * dt);
    return;
  }

  // path modes: the path clock slows down while the vehicle lags behind the reference
  const double lag = (p_ref_ - p).norm();
  const double half = 0.5 * params_.leash_m;
  const double rate = std::clamp((params_.leash_m - lag) / half, 0.0, 1.0);
  path_time_ = std::min(path_time_ + rate * dt, path_.duration_sec());
  const PathSample s = path_.Sample(path_time_);
  p_ref_ = s.position;
  v_ff_ = rate * s.velocity;
  a_ff_ = rate * s.acceleration;
  j_ff_ = rate * s.jerk;

  if (face_path_) {
    const auto& v = path_.vertices();
    const Eigen::Vector2d d = (v[s.segment + 1] - v[s.segment]).head<2>();
    if (d.norm() > 1e-3) yaw_target_ = std::atan2(d.y(), d.x());
  }
  const double err = PidWrapAngle(yaw_target_ - yaw_ref_);
  const double max_step = params_.yaw_speed_deg_s * kPidDegToRad * dt;
  const double step = std::clamp(err, -max_step, max_step);
  yaw_ref_ = PidWrapAngle(yaw_ref_ + step);
  yaw_rate_ff_ = step / dt;
}

void MultirotorPid::Compute(const ControlInput& input, std::span<double> ctrl) {
  using M = MultirotorCommand::Mode;
  const double t = input.time_sec();
  double dt = started_ ? t - t_prev_ : 1.0 / params_.rate_hz;
  if (!(dt > 0)) dt = 1.0 / params_.rate_hz;
  started_ = true;
  t_prev_ = t;

  const Pose X_WB = input.X_WB(base_);
  const Twist V_WB = input.V_WB(base_);
  const Eigen::Vector3d p = X_WB.translation();
  const Eigen::Matrix3d R = X_WB.linear();
  const Eigen::Vector3d v = V_WB.tail<3>();
  const Eigen::Vector3d w = R.transpose() * V_WB.head<3>();  // body rates
  auto yaw = [&R] { return std::atan2(R(1, 0), R(0, 0)); };  // only needed on mode changes

  // commands that are due: scripted first, then a programmatic one
  while (next_scripted_ < params_.commands.size() &&
         params_.commands[next_scripted_].t_sec <= t + 1e-9) {
    ApplyCommand(params_.commands[next_scripted_].command, p, yaw());
    ++next_scripted_;
  }
  if (has_pending_.load(std::memory_order_acquire)) {
    MultirotorCommand cmd;
    {
      std::lock_guard<std::mutex> lock(pending_mutex_);
      cmd = pending_;
      has_pending_.store(false, std::memory_order_relaxed);
    }
    ApplyCommand(cmd, p, yaw());
  }

  if (mode_ == M::kIdle) {
    for (size_t i = 0; i < rotors_.size(); ++i) {
      thrust_[i] = airframe_.min_thrust_n[i];
      ctrl[rotors_[i]] = thrust_[i];
    }
    p_ref_ = p;
    yaw_ref_ = yaw();
    return;
  }

  UpdateReference(dt, p);
  if (mode_ == M::kLand) {
    // touchdown: resting on something while the reference keeps sinking
    const bool resting = p.z() - p_ref_.z() > 0.3 && std::abs(v.z()) < 0.1;
    touchdown_sec_ = resting ? touchdown_sec_ + dt : 0;
    if (touchdown_sec_ >= 0.3) {
      mode_ = M::kIdle;
      for (size_t i = 0; i < rotors_.size(); ++i) {
        thrust_[i] = airframe_.min_thrust_n[i];
        ctrl[rotors_[i]] = thrust_[i];
      }
      return;
    }
  }

  // position P -> velocity setpoint
  Eigen::Vector3d v_sp = v_ff_;
  v_sp.head<2>() += params_.position_p_xy * (p_ref_ - p).head<2>();
  v_sp.z() += params_.position_p_z * (p_ref_.z() - p.z());
  const double sxy = v_sp.head<2>().norm();
  if (sxy > params_.max_speed_xy_m_s) v_sp.head<2>() *= params_.max_speed_xy_m_s / sxy;
  v_sp.z() = std::clamp(v_sp.z(), -params_.max_descent_m_s, params_.max_climb_m_s);

  // velocity PID -> acceleration setpoint (derivative on the measured velocity)
  if (dt != alpha_dt_) {
    alpha_dt_ = dt;
    alpha_ = LowPassAlpha(dt, params_.derivative_cutoff_hz);
  }
  const double alpha = alpha_;
  if (have_prev_) {
    acc_filt_ += alpha * ((v - v_prev_) / dt - acc_filt_);
    wdot_filt_ += alpha * ((w - w_prev_) / dt - wdot_filt_);
  }
  v_prev_ = v;
  w_prev_ = w;
  have_prev_ = true;
  const Eigen::Vector3d e_v = v_sp - v;
  const Eigen::Vector3d kp_v(params_.velocity_p_xy, params_.velocity_p_xy, params_.velocity_p_z);
  const Eigen::Vector3d ki_v(params_.velocity_i_xy, params_.velocity_i_xy, params_.velocity_i_z);
  const Eigen::Vector3d kd_v(params_.velocity_d_xy, params_.velocity_d_xy, params_.velocity_d_z);
  // integrate the clipped error unless the output saturated on that axis at the last update
  // or the thrust direction is far from its setpoint (the translational loop is open then)
  const Eigen::Vector3d e_i = e_v.cwiseMax(-kIntegratorErrorClip).cwiseMin(kIntegratorErrorClip);
  const bool attitude_ok = !tilt_error_large_;
  if (attitude_ok && !xy_limited_ && mix_.roll_pitch_scale >= 1)
    vel_int_.head<2>() += ki_v.head<2>().cwiseProduct(e_i.head<2>()) * dt;
  const bool z_blocked =
      mix_.collective_limited && ((mix_.collective_n < last_collective_request_) == (e_v.z() > 0));
  if (attitude_ok && !z_blocked) vel_int_.z() += ki_v.z() * e_i.z() * dt;
  const double ilim = params_.velocity_i_limit_m_s2;
  vel_int_ = vel_int_.cwiseMax(-ilim).cwiseMin(ilim);
  const Eigen::Vector3d a_sp =
      a_ff_ + kp_v.cwiseProduct(e_v) + vel_int_ - kd_v.cwiseProduct(acc_filt_);

  // thrust vector with tilt limit
  const double m = airframe_.mass_kg, g = params_.gravity_m_s2;
  Eigen::Vector3d F = m * (a_sp + Eigen::Vector3d(0, 0, g));
  F.z() = std::max(F.z(), 0.1 * m * g);
  const double fxy = F.head<2>().norm();
  const double fxy_max = F.z() * tan_max_tilt_;
  xy_limited_ = fxy > fxy_max;
  if (xy_limited_) F.head<2>() *= fxy_max / fxy;
  const Eigen::Vector3d b3 = F.normalized();
  tilt_error_large_ = b3.dot(R.col(2)) < kCosIntegratorMaxTiltError;
  const double collective = std::max(F.dot(R.col(2)), 0.0);

  // attitude setpoint: thrust direction b3 and reference yaw
  if (yaw_ref_ != heading_yaw_) {
    heading_yaw_ = yaw_ref_;
    heading_ = Eigen::Vector3d(std::cos(yaw_ref_), std::sin(yaw_ref_), 0);
  }
  const Eigen::Vector3d& heading = heading_;
  Eigen::Vector3d b2 = b3.cross(heading);
  if (b2.norm() < 1e-6)
    b2 = b3.cross(R.col(0));  // heading along the thrust (not reachable
                              // within the tilt limit; kept for safety)
  b2.normalize();
  Eigen::Matrix3d R_d;
  R_d.col(0) = b2.cross(b3);
  R_d.col(1) = b2;
  R_d.col(2) = b3;

  // attitude P on the quaternion error, thrust direction first, yaw weighted
  const Eigen::Quaterniond q(R);
  const Eigen::Quaterniond q_d(R_d);
  const Eigen::Quaterniond q_red =
      Eigen::Quaterniond::FromTwoVectors(R.col(2), b3) * q;  // reduced-attitude setpoint
  Eigen::Quaterniond q_mix = q_red.conjugate() * q_d;        // remaining rotation about b3
  if (q_mix.w() < 0) q_mix.coeffs() *= -1;
  const double yaw_weight =
      std::clamp(params_.attitude_p_yaw / params_.attitude_p_roll_pitch, 0.0, 1.0);
  const double mix_angle = 2 * std::atan2(q_mix.z(), q_mix.w()) * yaw_weight;
  const Eigen::Quaterniond q_cmd =
      q_red * Eigen::Quaterniond(Eigen::AngleAxisd(mix_angle, Eigen::Vector3d::UnitZ()));
  Eigen::Quaterniond q_e = q.conjugate() * q_cmd;
  if (q_e.w() < 0) q_e.coeffs() *= -1;
  Eigen::Vector3d w_sp = 2 * params_.attitude_p_roll_pitch * q_e.vec();
  w_sp += R.transpose().col(2) * yaw_rate_ff_;  // world yaw rate in body axes
  const Eigen::Vector3d b3_dot = (m / F.norm()) * (j_ff_ - j_ff_.dot(b3) * b3);
  w_sp += R.transpose() * b3.cross(b3_dot);
  const double rp_max = params_.max_roll_pitch_rate_deg_s * kPidDegToRad;
  const double yaw_max = params_.max_yaw_rate_deg_s * kPidDegToRad;
  w_sp.x() = std::clamp(w_sp.x(), -rp_max, rp_max);
  w_sp.y() = std::clamp(w_sp.y(), -rp_max, rp_max);
  w_sp.z() = std::clamp(w_sp.z(), -yaw_max, yaw_max);

  // rate PID -> torque (with gyroscopic compensation)
  const Eigen::Vector3d e_w = w_sp - w;
  const Eigen::Vector3d kp_w(params_.rate_p_roll_pitch, params_.rate_p_roll_pitch,
                             params_.rate_p_yaw);
  const Eigen::Vector3d ki_w(params_.rate_i_roll_pitch, params_.rate_i_roll_pitch,
                             params_.rate_i_yaw);
  const Eigen::Vector3d kd_w(params_.rate_d_roll_pitch, params_.rate_d_roll_pitch,
                             params_.rate_d_yaw);
  if (mix_.roll_pitch_scale >= 1)
    rate_int_.head<2>() += ki_w.head<2>().cwiseProduct(e_w.head<2>()) * dt;
  if (mix_.yaw_scale >= 1) rate_int_.z() += ki_w.z() * e_w.z() * dt;
  const double rlim = params_.rate_i_limit_rad_s2;
  rate_int_ = rate_int_.cwiseMax(-rlim).cwiseMin(rlim);
  const Eigen::Vector3d alpha_sp =
      kp_w.cwiseProduct(e_w) + rate_int_ - kd_w.cwiseProduct(wdot_filt_);
  const Eigen::Matrix3d& J = airframe_.inertia_B;
  const Eigen::Vector3d torque = J * alpha_sp + w.cross(J * w);

  // mixer -> rotor thrusts
  last_collective_request_ = collective;
  mix_ = mixer_.Mix(collective, torque, thrust_);
  for (size_t i = 0; i < rotors_.size(); ++i) ctrl[rotors_[i]] = thrust_[i];
}

}  // namespace penumbra
