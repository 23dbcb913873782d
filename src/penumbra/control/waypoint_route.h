#pragma once
// progress along a list of world-frame (x, y) waypoints: which one is the current goal,
// how many were reached, whether the route is done. shared by the controllers that steer
// through waypoints with control/pure_pursuit.h (waypoint_follower, trot_gait).
//
// a waypoint is reached when the robot's position comes within `tolerance_m` of it; the
// goal then advances to the next one, wrapping to the first after the last when looping,
// otherwise the route is finished for good after the last one.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace penumbra {

/// the waypoint sequence and the progress along it (see the file comment).
class WaypointRoute {
 public:
  /// `waypoints`: world x, y (m), at least 1; `tolerance_m` > 0. the caller validates.
  WaypointRoute(std::vector<Eigen::Vector2d> waypoints, bool loop, double tolerance_m);

  /// marks as reached every goal within the tolerance of `p_W` (world x, y, m), at most
  /// one lap per call, and moves the goal on.
  void Advance(const Eigen::Vector2d& p_W);
  /// back to the first waypoint, nothing reached.
  void Reset();

  /// the current goal (world x, y, m); the last waypoint once finished.
  const Eigen::Vector2d& target() const { return waypoints_[target_]; }
  /// index of the current goal in waypoints().
  int target_index() const { return target_; }
  /// waypoints reached so far (counts every lap when looping).
  int64_t reached() const { return reached_; }
  /// true once the last waypoint was reached and loop is false.
  bool finished() const { return finished_; }
  const std::vector<Eigen::Vector2d>& waypoints() const { return waypoints_; }

 private:
  std::vector<Eigen::Vector2d> waypoints_;
  bool loop_ = true;
  double tolerance_m_ = 0.15;
  int target_ = 0;
  int64_t reached_ = 0;
  bool finished_ = false;
};

}  // namespace penumbra
