#include "penumbra/control/pure_pursuit.h"

#include <algorithm>
#include <cmath>

namespace penumbra {
namespace {

// a wrapped into (-pi, pi]
double PursuitWrapAngle(double a) {
  a = std::remainder(a, 2 * M_PI);  // in [-pi, pi]
  return a <= -M_PI ? a + 2 * M_PI : a;
}

}  // namespace

UnicycleCommand PurePursuit(const Pose& X_WB, const Eigen::Vector2d& goal_W,
                            const PurePursuitLimits& limits) {
  UnicycleCommand cmd;
  const Eigen::Vector2d p = X_WB.translation().head<2>();
  const Eigen::Vector2d forward = X_WB.linear().col(0).head<2>();
  if (forward.norm() <= 1e-3) return cmd;
  const Eigen::Vector2d to_goal = goal_W - p;
  const double d = to_goal.norm();
  const double psi = std::atan2(forward.y(), forward.x());
  const double alpha = PursuitWrapAngle(std::atan2(to_goal.y(), to_goal.x()) - psi);
  const double omega_max = limits.max_yaw_rate;
  if (std::abs(alpha) > 0.5 * M_PI) {
    // goal behind: turn in place
    cmd.yaw_rate = alpha > 0 ? omega_max : -omega_max;
    return cmd;
  }
  // arc through the goal, speed capped by the yaw-rate limit
  const double kappa = 2.0 * std::sin(alpha) / std::max(d, 1e-9);
  double v = limits.speed_m_s;
  if (std::abs(v * kappa) > omega_max) v = omega_max / std::abs(kappa);
  cmd.v_m_s = v;
  cmd.yaw_rate = v * kappa;
  return cmd;
}

}  // namespace penumbra
