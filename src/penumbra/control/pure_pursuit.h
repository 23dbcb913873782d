#pragma once
// pure pursuit towards one goal point, for robots commanded by a forward speed and a yaw
// rate (unicycle model): differential-drive rovers (control/waypoint_follower.h) and
// walking robots following a twist (control/trot_gait.h) share this law.
//
// with robot position p and heading psi (yaw of the base body's x axis in the world xy
// plane) and goal point g:
//   d = |g - p|, alpha = wrap(atan2(g - p) - psi) (heading error, in (-pi, pi]);
//   |alpha| > 90 deg (goal behind): turn in place, v = 0, omega = sign(alpha) omega_max;
//   otherwise the circular arc through p tangent to the heading and through g (R. C.
//   Coulter, "Implementation of the Pure Pursuit Path Tracking Algorithm", CMU-RI-TR-92-01,
//   1992): curvature kappa = 2 sin(alpha) / d, v = speed reduced until |v kappa| <=
//   omega_max, omega = v kappa.
// if the base body's x axis points (nearly) straight up or down, the command is zero.

#include <Eigen/Core>

#include "penumbra/core/pose.h"

namespace penumbra {

/// limits of a pure-pursuit command.
struct PurePursuitLimits {
  double speed_m_s = 0.5;     ///< cruise speed (m/s, > 0)
  double max_yaw_rate = 1.5;  ///< largest |yaw rate| (rad/s, > 0)
};

/// a unicycle command: forward speed along the base body's x axis and yaw rate.
struct UnicycleCommand {
  double v_m_s = 0;     ///< forward speed (m/s)
  double yaw_rate = 0;  ///< rad/s, counter-clockwise seen from above
};

/// the pure-pursuit command (see the file comment) that steers the base body with pose
/// `X_WB` (world frame; its x axis is the robot's forward direction) towards the world
/// point `goal_W` (x, y in m) within `limits`.
UnicycleCommand PurePursuit(const Pose& X_WB, const Eigen::Vector2d& goal_W,
                            const PurePursuitLimits& limits);

}  // namespace penumbra
