#include "penumbra/control/waypoint_follower.h"

#include <algorithm>
#include <cmath>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

double WrapAngle(double a) {
  a = std::remainder(a, 2 * M_PI);  // in [-pi, pi]
  return a <= -M_PI ? a + 2 * M_PI : a;
}

}  // namespace

WaypointFollowerParams WaypointFollowerParams::Parse(ControllerParams& p,
                                                     const std::string& name_prefix) {
  WaypointFollowerParams w;
  w.base_body = name_prefix + p.String("base_body");
  w.left_actuator = name_prefix + p.String("left_actuator");
  w.right_actuator = name_prefix + p.String("right_actuator");
  w.wheel_radius_m = p.Number("wheel_radius_m", std::nullopt, 0, kInf, true);
  w.track_width_m = p.Number("track_width_m", std::nullopt, 0, kInf, true);
  w.speed_m_s = p.Number("speed_m_s", 0.5, 0, kInf, true);
  w.max_yaw_rate_deg_s = p.Number("max_yaw_rate_deg_s", 90, 0, kInf, true);
  w.waypoints = p.Points2("waypoints", 1);
  w.loop = p.Bool("loop", true);
  w.tolerance_m = p.Number("tolerance_m", 0.15, 0, kInf, true);
  w.rate_hz = p.Number("rate_hz", 50, 0, kInf, true);
  p.CheckNoUnknownKeys();
  if (w.left_actuator == w.right_actuator)
    p.Fail("right_actuator", "same actuator as left_actuator ('" + w.left_actuator +
                                 "'); expected two different wheel actuators");
  return w;
}

void WaypointFollowerParams::ValidateOrThrow(const ControllerContext& c) const {
  auto fail = [&](const std::string& key, const std::string& problem) {
    throw ConfigError(c.file, c.line, c.key.empty() ? key : c.key + "." + key, problem);
  };
  auto positive = [&](const char* key, double v) {
    if (!(std::isfinite(v) && v > 0))
      fail(key, "got " + std::to_string(v) + "; expected a number > 0");
  };
  if (base_body.empty()) fail("base_body", "missing; expected a body name");
  if (left_actuator.empty()) fail("left_actuator", "missing; expected an actuator name");
  if (right_actuator.empty()) fail("right_actuator", "missing; expected an actuator name");
  if (left_actuator == right_actuator)
    fail("right_actuator", "same actuator as left_actuator; expected two different actuators");
  positive("wheel_radius_m", wheel_radius_m);
  positive("track_width_m", track_width_m);
  positive("speed_m_s", speed_m_s);
  positive("max_yaw_rate_deg_s", max_yaw_rate_deg_s);
  positive("tolerance_m", tolerance_m);
  positive("rate_hz", rate_hz);
  if (waypoints.empty()) fail("waypoints", "empty; expected at least 1 [x, y] point");
  for (const auto& w : waypoints)
    if (!w.allFinite()) fail("waypoints", "non-finite coordinate; expected finite numbers (m)");
}

WaypointFollower::WaypointFollower(WaypointFollowerParams params, ControllerContext context)
    : Controller(std::move(context)), params_(std::move(params)) {
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
  target_ = 0;
  reached_ = 0;
  finished_ = false;
}

void WaypointFollower::Compute(const ControlInput& input, std::span<double> ctrl) {
  const Pose X_WB = input.X_WB(base_body_);
  const Eigen::Vector2d p = X_WB.translation().head<2>();
  const Eigen::Vector2d forward = X_WB.linear().col(0).head<2>();
  const double omega_max = params_.max_yaw_rate_deg_s * M_PI / 180.0;
  const int n = static_cast<int>(params_.waypoints.size());

  // advance past reached waypoints (at most one lap per update)
  for (int k = 0; k < n && !finished_; ++k) {
    if ((params_.waypoints[target_] - p).norm() >= params_.tolerance_m) break;
    ++reached_;
    if (target_ + 1 < n) {
      ++target_;
    } else if (params_.loop) {
      target_ = 0;
    } else {
      finished_ = true;
    }
  }

  double v = 0, omega = 0;
  if (!finished_ && forward.norm() > 1e-3) {
    const Eigen::Vector2d to_target = params_.waypoints[target_] - p;
    const double d = to_target.norm();
    const double psi = std::atan2(forward.y(), forward.x());
    const double alpha = WrapAngle(std::atan2(to_target.y(), to_target.x()) - psi);
    if (std::abs(alpha) > 0.5 * M_PI) {
      // target behind: turn in place
      omega = alpha > 0 ? omega_max : -omega_max;
    } else {
      // pure pursuit towards the waypoint, speed capped by the yaw-rate limit
      const double kappa = 2.0 * std::sin(alpha) / std::max(d, 1e-9);
      v = params_.speed_m_s;
      if (std::abs(v * kappa) > omega_max) v = omega_max / std::abs(kappa);
      omega = v * kappa;
    }
  }
  v_ = v;
  omega_ = omega;
  const double half_track = 0.5 * params_.track_width_m;
  ctrl[left_] = (v - omega * half_track) / params_.wheel_radius_m;
  ctrl[right_] = (v + omega * half_track) / params_.wheel_radius_m;
}

}  // namespace penumbra
