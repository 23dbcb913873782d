#pragma once
// foot trajectory of a swing leg: a cycloid from lift-off to touch-down. with phase
// s in [0, 1] and duration T_sw:
//   sigma(s) = s - sin(2 pi s) / (2 pi)                 (0 -> 1, zero slope at both ends)
//   p_xy(s)  = p0_xy + (p1_xy - p0_xy) sigma(s)
//   p_z(s)   = p0_z + (p1_z - p0_z) sigma(s) + h (1 - cos(2 pi s)) / 2
// so the foot leaves and meets the ground with zero velocity and peaks at height h above
// the straight line at mid-swing (the cycloid profile of Y. Sakakibara et al., "Foot
// Trajectory for a Quadruped Walking Machine", IROS 1990).

#include <Eigen/Core>

namespace penumbra {

/// a point of the swing trajectory.
struct SwingSample {
  Eigen::Vector3d p;  ///< position (world frame, m)
  Eigen::Vector3d v;  ///< velocity (world frame, m/s)
};

/// the swing trajectory from `p0` (lift-off) to `p1` (touch-down) with apex height
/// `height_m` at phase `s` (clamped to [0, 1]) of a swing lasting `duration_sec` (> 0).
SwingSample CycloidSwing(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, double height_m,
                         double s, double duration_sec);

}  // namespace penumbra
