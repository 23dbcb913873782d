#pragma once
// planar velocity commands for legged and wheeled base controllers: the twist (vx, vy forward /
// left in the heading frame, m/s; yaw rate, rad/s): the command source shared by controllers
// that take them (trot_gait's keys). the command bus reaches such a controller through its
// TwistTarget and WaypointTarget interfaces (control/controller_capabilities.h).
//
// world-file keys TwistCommandSource reads (inside the controller block):
//   commands:                      # scripted twist, held from each t (s) to the next
//     - {t: 0, vx: 0, vy: 0, yaw_rate: 0}
//     - {t: 1, vx: 0.5}            # missing components are 0
//   waypoints: [[1, 0], [1, 1]]    # waypoint mode: world x, y (m) of the base body's origin,
//                                  # at least 1 (the next four keys only with it)
//   loop: true                     # after the last waypoint, start again (default true)
//   speed_m_s: 0.5                 # > 0, cruise speed along the route (default 0.5)
//   max_yaw_rate_deg_s: 60         # > 0, yaw-rate limit of the route (default 60)
//   tolerance_m: 0.15              # > 0, a waypoint within this radius is reached (0.15)
//
// precedence at each update: the programmatic override (SetCommand, until ClearCommand) >
// the waypoint route while it is not finished (pure pursuit, control/pure_pursuit.h: vx = v,
// vy = 0, yaw_rate = omega) > the scripted entry with the largest t_i <= t (zero before the
// first and without a script).

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "penumbra/control/controller_capabilities.h"
#include "penumbra/control/controller_params.h"
#include "penumbra/control/waypoint_route.h"
#include "penumbra/core/pose.h"

namespace penumbra {

// TrotCommand (a twist) and the TwistTarget / WaypointTarget interfaces of the controllers
// that take them: control/controller_capabilities.h.

/// one scripted command, active from `t_sec` until the next entry.
struct TimedTrotCommand {
  double t_sec = 0;
  TrotCommand command;
};

/// the scripted commands and route of a controller block (see the file comment).
struct TwistScriptParams {
  std::vector<TimedTrotCommand> commands;
  std::vector<Eigen::Vector2d> waypoints;  ///< world x, y (m); empty = no waypoint mode
  bool loop = true;
  double speed_m_s = 0.5;
  double max_yaw_rate_deg_s = 60;
  double tolerance_m = 0.15;

  /// reads `commands`, `waypoints`, `loop`, `speed_m_s`, `max_yaw_rate_deg_s`, `tolerance_m`.
  /// @throws ConfigError naming the key for bad values, non-increasing times and route keys
  ///         without waypoints.
  static TwistScriptParams Parse(ControllerParams& params);
};

/// the command in force at each update (see the file comment). not thread-safe.
class TwistCommandSource {
 public:
  explicit TwistCommandSource(TwistScriptParams params);

  /// the command at time `t` (s) for a base at X_WB; advances the route while it is in force.
  TrotCommand Update(double t, const Pose& X_WB);
  /// the scripted entry in force at `t` (zero before the first).
  TrotCommand Scripted(double t) const;

  void SetCommand(const TrotCommand& command) { override_ = command; }
  void ClearCommand() { override_.reset(); }
  /// @throws Error (prefixed with `label`) for an empty list or a non-finite coordinate.
  void SetWaypoints(std::vector<Eigen::Vector2d> waypoints, bool loop, const std::string& label);
  /// restarts the configured route (if any).
  void Reset();

  const TwistScriptParams& params() const { return params_; }
  /// progress along the route; nullptr without waypoint mode.
  const WaypointRoute* route() const { return route_ ? &*route_ : nullptr; }

 private:
  TwistScriptParams params_;
  std::optional<TrotCommand> override_;
  std::optional<WaypointRoute> route_;
};

}  // namespace penumbra
