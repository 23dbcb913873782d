#include "penumbra/control/waypoint_route.h"

#include <utility>

namespace penumbra {

WaypointRoute::WaypointRoute(std::vector<Eigen::Vector2d> waypoints, bool loop, double tolerance_m)
    : waypoints_(std::move(waypoints)), loop_(loop), tolerance_m_(tolerance_m) {}

void WaypointRoute::Advance(const Eigen::Vector2d& p_W) {
  const int n = static_cast<int>(waypoints_.size());
  for (int k = 0; k < n && !finished_; ++k) {
    if ((waypoints_[target_] - p_W).norm() >= tolerance_m_) break;
    ++reached_;
    if (target_ + 1 < n) {
      ++target_;
    } else if (loop_) {
      target_ = 0;
    } else {
      finished_ = true;
    }
  }
}

void WaypointRoute::Reset() {
  target_ = 0;
  reached_ = 0;
  finished_ = false;
}

}  // namespace penumbra
