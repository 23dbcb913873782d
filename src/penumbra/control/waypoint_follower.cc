#include "penumbra/control/waypoint_follower.h"

#include <algorithm>
#include <cmath>

#include "penumbra/control/param_check.h"
#include "penumbra/control/param_limits.h"
#include "penumbra/control/pure_pursuit.h"
#include "penumbra/core/error.h"

namespace penumbra {
WaypointFollowerParams WaypointFollowerParams::Parse(ControllerParams& p,
                                                     const std::string& name_prefix) {
  WaypointFollowerParams w;
  w.base_body = name_prefix + p.String("base_body");
  w.left_actuator = name_prefix + p.String("left_actuator");
  w.right_actuator = name_prefix + p.String("right_actuator");
  w.wheel_radius_m = p.Number("wheel_radius_m", std::nullopt, 0, kMaxParamPositionM, true);
  w.track_width_m = p.Number("track_width_m", std::nullopt, 0, kMaxParamPositionM, true);
  w.speed_m_s = p.Number("speed_m_s", 0.5, 0, kMaxParamSpeedMS, true);
  w.max_yaw_rate_deg_s = p.Number("max_yaw_rate_deg_s", 90, 0, kMaxParamAngularSpeedDegS, true);
  w.waypoints = p.Points2("waypoints", 1);
  w.loop = p.Bool("loop", true);
  w.tolerance_m = p.Number("tolerance_m", 0.15, 0, kMaxParamPositionM, true);
  w.rate_hz = p.Number("rate_hz", 50, 0, kMaxParamRateHz, true);
  p.CheckNoUnknownKeys();
  if (w.left_actuator == w.right_actuator)
    p.Fail("right_actuator", "same actuator as left_actuator ('" + w.left_actuator +
                                 "'); expected two different wheel actuators");
  return w;
}

void WaypointFollowerParams::ValidateOrThrow(const ControllerContext& c) const {
  const ParamCheck check(c);
  if (base_body.empty()) check.Fail("base_body", "missing; expected a body name");
  if (left_actuator.empty()) check.Fail("left_actuator", "missing; expected an actuator name");
  if (right_actuator.empty()) check.Fail("right_actuator", "missing; expected an actuator name");
  if (left_actuator == right_actuator)
    check.Fail("right_actuator",
               "same actuator as left_actuator; expected two different actuators");
  check.Positive("wheel_radius_m", wheel_radius_m);
  check.Positive("track_width_m", track_width_m);
  check.Positive("speed_m_s", speed_m_s);
  check.Positive("max_yaw_rate_deg_s", max_yaw_rate_deg_s);
  check.Positive("tolerance_m", tolerance_m);
  check.Positive("rate_hz", rate_hz);
  if (waypoints.empty()) check.Fail("waypoints", "empty; expected at least 1 [x, y] point");
  for (const auto& w : waypoints)
    if (!w.allFinite())
      check.Fail("waypoints", "non-finite coordinate; expected finite numbers (m)");
}

WaypointFollower::WaypointFollower(WaypointFollowerParams params, ControllerContext context)
    : Controller(std::move(context)),
      params_(std::move(params)),
      route_(params_.waypoints, params_.loop, params_.tolerance_m) {
  params_.ValidateOrThrow(this->context());
}

std::vector<NameRequirement> WaypointFollower::RequiredNames() const {
  return {{ModelObject::kBody, params_.base_body, "base_body"},
          {ModelObject::kActuator, params_.left_actuator, "left_actuator"},
          {ModelObject::kActuator, params_.right_actuator, "right_actuator"}};
}

void WaypointFollower::OnInitialize(const ModelInfo& model, const std::vector<int>& ids) {
  base_body_ = ids[0];
  left_ = ids[1];
  right_ = ids[2];
  const ControllerContext& c = context();
  for (int k : {1, 2}) {
    const ActuatorInfo& a = model.actuators[ids[k]];
    const char* key = k == 1 ? "left_actuator" : "right_actuator";
    if (a.joint < 0 || model.joints[a.joint].type != JointInfo::Type::kHinge)
      throw ConfigError(c.file, c.line, c.key + "." + key,
                        "actuator '" + a.name +
                            "' does not drive a hinge joint; expected a velocity actuator on a "
                            "wheel's hinge joint");
  }
  Reset();
}

void WaypointFollower::Reset() {
  route_ = WaypointRoute(params_.waypoints, params_.loop, params_.tolerance_m);
  v_ = omega_ = 0;
  start_.reset();
  twist_.reset();
  tracking_ = {NAN, NAN};
}

void WaypointFollower::SetTwist(const TrotCommand& command) {
  const double v_m_s = command.vx, yaw_rate = command.yaw_rate;
  if (!std::isfinite(v_m_s) || !std::isfinite(yaw_rate))
    throw Error(label() + ": twist must be finite (got v " + std::to_string(v_m_s) +
                " m/s, yaw rate " + std::to_string(yaw_rate) + " rad/s)");
  if (command.vy != 0)
    throw Error(label() + ": a differential drive cannot move sideways; vy must be 0 (got " +
                std::to_string(command.vy) + " m/s)");
  twist_ = std::array<double, 2>{v_m_s, yaw_rate};
}

void WaypointFollower::SetWaypoints(std::vector<Eigen::Vector2d> waypoints, bool loop) {
  if (waypoints.empty()) throw Error(label() + ": empty waypoint list; expected at least 1");
  for (const auto& w : waypoints)
    if (!w.allFinite()) throw Error(label() + ": non-finite waypoint coordinate");
  route_ = WaypointRoute(std::move(waypoints), loop, params_.tolerance_m);
  start_.reset();
  twist_.reset();
}

void WaypointFollower::Compute(const ControlInput& input, std::span<double> ctrl) {
  const Pose X_WB = input.X_WB(base_body_);
  const Eigen::Vector2d p = X_WB.translation().head<2>();
  if (!start_) start_ = p;
  route_.Advance(p);
  // tracking error: distance from the segment (previous waypoint or start) -> goal
  {
    const auto& w = route_.waypoints();
    const int k = route_.target_index();
    const Eigen::Vector2d a = k > 0                                    ? w[k - 1]
                              : (params_.loop && route_.reached() > 0) ? w.back()
                                                                       : *start_;
    const Eigen::Vector2d ab = route_.target() - a;
    const double len2 = ab.squaredNorm();
    const double s = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
    tracking_ = {(a + s * ab - p).norm(), (route_.target() - p).norm()};
  }
  UnicycleCommand cmd;
  if (twist_) {
    cmd.v_m_s = (*twist_)[0];
    cmd.yaw_rate = (*twist_)[1];
  } else if (!route_.finished())
    cmd = PurePursuit(X_WB, route_.target(),
                      {params_.speed_m_s, params_.max_yaw_rate_deg_s * M_PI / 180.0});
  v_ = cmd.v_m_s;
  omega_ = cmd.yaw_rate;
  const double half_track = 0.5 * params_.track_width_m;
  ctrl[left_] = (v_ - omega_ * half_track) / params_.wheel_radius_m;
  ctrl[right_] = (v_ + omega_ * half_track) / params_.wheel_radius_m;
}

}  // namespace penumbra
