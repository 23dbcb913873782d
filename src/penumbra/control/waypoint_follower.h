#pragma once
// differential-drive waypoint follower: steers a two-wheeled robot through a list
// of world-frame (x, y) points.
//
// world-file block (robot-local names get the "<robot>/" prefix):
//   controller:
//     type: waypoint_follower
//     base_body: chassis        # body whose x axis is the robot's forward direction
//     left_actuator: left_wheel # velocity actuators: ctrl = wheel angular velocity (rad/s)
//     right_actuator: right_wheel
//     wheel_radius_m: 0.05      # > 0
//     track_width_m: 0.3        # > 0, distance between the wheels' contact points
//     speed_m_s: 0.5            # > 0, cruise speed (default 0.5)
//     max_yaw_rate_deg_s: 90    # > 0 (default 90)
//     waypoints: [[1.0, 0.0], [1.0, 1.0]]   # world x, y (m), at least 1
//     loop: true                # after the last waypoint, start again (default true)
//     tolerance_m: 0.15         # > 0, a waypoint counts as reached inside this radius
//                               # (default 0.15)
//     rate_hz: 50               # > 0, control rate on sim time (default 50)
//
// wheel convention: a positive ctrl must drive its wheel forward, i.e. the wheel
// hinge axes point to the robot's left (+y of the base body), as in REP-103.
//
// control law, at each update, with robot position p (the base body's origin) and heading
// psi (yaw of the base body's x axis in the world xy plane):
//   1. the waypoint progress of control/waypoint_route.h: every waypoint within
//      tolerance_m of p is reached and the goal w advances to the next (wrapping when
//      loop, otherwise the robot stops for good after the last one).
//   2.-3. the pure-pursuit law of control/pure_pursuit.h towards w: turn in place at
//      omega_max while w lies more than 90 deg off the heading, otherwise drive the arc
//      of curvature kappa = 2 sin(alpha) / |w - p| at speed_m_s, reduced until
//      |v kappa| <= omega_max (R. C. Coulter, "Implementation of the Pure Pursuit Path
//      Tracking Algorithm", CMU-RI-TR-92-01, 1992).
//   4. differential-drive inverse kinematics (R. Siegwart, I. Nourbakhsh,
//      D. Scaramuzza, "Introduction to Autonomous Mobile Robots", 2nd ed., 2011,
//      sec. 3.2.1): wheel rates (v -/+ omega track/2) / wheel_radius (left/right).
// if the base body's x axis points (nearly) straight up or down, the robot stops.

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "penumbra/control/controller.h"
#include "penumbra/control/controller_capabilities.h"
#include "penumbra/control/controller_params.h"
#include "penumbra/control/waypoint_route.h"

namespace penumbra {

/// parameters of a WaypointFollower (see the file comment for meanings and ranges).
struct WaypointFollowerParams {
  std::string base_body;       ///< full model name, e.g. "rover/chassis"
  std::string left_actuator;   ///< full model name
  std::string right_actuator;  ///< full model name
  double wheel_radius_m = 0.05;
  double track_width_m = 0.3;
  double speed_m_s = 0.5;
  double max_yaw_rate_deg_s = 90;
  std::vector<Eigen::Vector2d> waypoints;  ///< world frame x, y (m)
  bool loop = true;
  double tolerance_m = 0.15;
  double rate_hz = 50;

  /// reads the keys above from `params`; local names get `name_prefix` ("rover/" or "").
  /// @throws ConfigError for missing/unknown keys and out-of-range values.
  static WaypointFollowerParams Parse(ControllerParams& params, const std::string& name_prefix);
  /// @throws ConfigError (in `context`) if a value is out of range.
  void ValidateOrThrow(const ControllerContext& context) const;
};

/// differential-drive waypoint follower (see the file comment).
class WaypointFollower final : public Controller, public TwistTarget, public WaypointTarget {
 public:
  /// @throws ConfigError if `params` are out of range.
  WaypointFollower(WaypointFollowerParams params, ControllerContext context);

  std::string type() const override { return "waypoint_follower"; }
  double rate_hz() const override { return params_.rate_hz; }
  std::vector<NameRequirement> RequiredNames() const override;
  void Compute(const ControlInput& input, std::span<double> ctrl) override;
  /// forgets the start point, the twist override and SetWaypoints: the configured route
  /// restarts.
  void Reset() override;
  /// "cross_track_m": distance of the base body's origin (world xy) from the path segment
  /// being followed (the previous waypoint, or the start position before the first one is
  /// reached, to the current goal); "goal_distance_m": its distance to the current goal.
  std::vector<std::string> tracking_error_labels() const override {
    return {"cross_track_m", "goal_distance_m"};
  }
  void AppendTrackingError(std::vector<double>* out) const override {
    out->insert(out->end(), tracking_.begin(), tracking_.end());
  }

  /// programmatic twist (e.g. a middleware's cmd_vel): from the next update on, the robot
  /// drives at forward speed command.vx (m/s) and yaw rate command.yaw_rate (rad/s,
  /// counter-clockwise seen from above) instead of following the route, until ClearTwist()
  /// (the route pauses meanwhile). call from the thread that steps the simulation, between
  /// steps. @throws Error for a non-finite value or vy != 0 (a differential drive).
  void SetTwist(const TrotCommand& command) override;
  /// back to the route.
  void ClearTwist() override { twist_.reset(); }
  /// a differential drive cannot move sideways.
  bool lateral() const override { return false; }
  /// replaces the route by `waypoints` (world x, y, m; at least 1) with `loop`, from the next
  /// update on, and clears a twist; the tolerance, speed and yaw-rate limit stay. physics
  /// thread, between steps. @throws Error for an empty list or a non-finite coordinate.
  void SetWaypoints(std::vector<Eigen::Vector2d> waypoints, bool loop) override;

  const WaypointFollowerParams& params() const { return params_; }
  /// index of the waypoint being driven to.
  int target_index() const { return route_.target_index(); }
  /// waypoints reached so far (counts every lap when looping).
  int64_t waypoints_reached() const { return route_.reached(); }
  /// true once the last waypoint was reached and loop is false; the robot then stands still.
  bool finished() const { return route_.finished(); }
  /// last commanded forward speed (m/s) and yaw rate (rad/s).
  double commanded_speed_m_s() const { return v_; }
  double commanded_yaw_rate() const { return omega_; }

 protected:
  void OnInitialize(const ModelInfo& model, const std::vector<int>& ids) override;

 private:
  WaypointFollowerParams params_;
  int base_body_ = -1, left_ = -1, right_ = -1;
  WaypointRoute route_;
  double v_ = 0, omega_ = 0;
  std::optional<Eigen::Vector2d> start_;         ///< base origin at the first update (world xy, m)
  std::optional<std::array<double, 2>> twist_;   ///< SetTwist: v (m/s), yaw rate (rad/s)
  std::array<double, 2> tracking_ = {NAN, NAN};  ///< see tracking_error_labels()
};

}  // namespace penumbra
