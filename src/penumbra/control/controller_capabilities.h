#pragma once
// what a controller accepts from the command bus (command/command_dispatcher.h: the `twist`,
// `waypoints` and `joint_targets` requests of the ZeroMQ and ROS bridges, the viewer's teleop,
// the navigation baseline): one capability interface per kind of command. a controller
// implements the ones it takes (TrotGait and PolicyController: TwistTarget and WaypointTarget;
// WaypointFollower: the same, without sideways motion; JointPdController: JointTarget), and
// code outside control/ finds them with the As*Target functions below, never by casting to a
// concrete controller class (ctest -R ArchitectureChecks checks it). ControllerCommands lists
// a controller's command names from the interfaces it implements (model_info's "commands").
// TerrainRayCasterUser is the one capability that is not a command: a controller that casts
// rays onto the static scene (a policy's height scan) gets the caster from the session.
//
// all methods are called from the thread that steps the simulation, between steps, and take
// effect at the next control update.

#include <Eigen/Core>
#include <string>
#include <vector>

namespace penumbra {

class Controller;
class TerrainRayCaster;

/// a twist command in the robot's heading frame.
struct TrotCommand {
  double vx = 0;        ///< forward speed (m/s)
  double vy = 0;        ///< leftward speed (m/s)
  double yaw_rate = 0;  ///< rad/s, counter-clockwise seen from above
};

/// a joint-space command: one value per joint of the controller, in its joint order.
struct JointCommand {
  enum class Mode { kPosition, kVelocity, kEffort };
  Mode mode = Mode::kPosition;
  std::vector<double> values;  ///< (n) rad or m / rad/s or m/s / N m or N

  static JointCommand Position(std::vector<double> q) { return {Mode::kPosition, std::move(q)}; }
  static JointCommand Velocity(std::vector<double> qd) { return {Mode::kVelocity, std::move(qd)}; }
  static JointCommand Effort(std::vector<double> tau) { return {Mode::kEffort, std::move(tau)}; }
};

/// a base controller that follows a programmatic twist (the `twist` command).
class TwistTarget {
 public:
  virtual ~TwistTarget() = default;
  /// follows `command` instead of its route or script until ClearTwist().
  /// @throws Error for a non-finite value, or vy != 0 when !lateral().
  virtual void SetTwist(const TrotCommand& command) = 0;
  /// back to the route (if any and not finished), else the script.
  virtual void ClearTwist() = 0;
  /// true when the base can move sideways (vy); false for a differential drive.
  virtual bool lateral() const = 0;
};

/// a base controller that follows a waypoint route (the `waypoints` command).
class WaypointTarget {
 public:
  virtual ~WaypointTarget() = default;
  /// replaces the route (world x, y, m; at least 1) and clears a SetTwist override.
  /// @throws Error for an empty list or a non-finite coordinate.
  virtual void SetWaypoints(std::vector<Eigen::Vector2d> waypoints, bool loop) = 0;
};

/// a joint-space controller (the `joint_targets` command).
class JointTarget {
 public:
  virtual ~JointTarget() = default;
  /// the joints of its command vectors, in order (MJCF names).
  virtual const std::vector<std::string>& command_joints() const = 0;
  /// replaces every queued command by `command` (latest wins).
  /// @throws Error if its size is not command_joints().size(), a value is not finite, or the
  ///         mode cannot be applied (effort with position output).
  virtual void SetCommand(JointCommand command) = 0;
};

/// a controller that casts rays onto the terrain (control/terrain_ray_caster.h).
class TerrainRayCasterUser {
 public:
  virtual ~TerrainRayCasterUser() = default;
  /// whether it casts rays at all (e.g. a policy with a height_scan observation term).
  virtual bool needs_terrain_ray_caster() const = 0;
  /// the caster to use (not owned; must outlive the controller).
  virtual void SetTerrainRayCaster(const TerrainRayCaster* caster) = 0;
};

/// the capability of `controller`, or nullptr when it does not have it.
TwistTarget* AsTwistTarget(Controller& controller);
WaypointTarget* AsWaypointTarget(Controller& controller);
JointTarget* AsJointTarget(Controller& controller);
const TwistTarget* AsTwistTarget(const Controller& controller);
const WaypointTarget* AsWaypointTarget(const Controller& controller);
const JointTarget* AsJointTarget(const Controller& controller);
TerrainRayCasterUser* AsTerrainRayCasterUser(Controller& controller);

/// the command names `controller` accepts, from the interfaces it implements, in this order:
/// "twist" (TwistTarget), "waypoints" (WaypointTarget), "joint_targets" (JointTarget).
std::vector<std::string> ControllerCommands(const Controller& controller);

}  // namespace penumbra
