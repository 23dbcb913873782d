#pragma once
// builds controllers from world-file `controller:` blocks.
//
// types (the `type:` key):
//   diff_ik            differential inverse kinematics for arms (control/diff_ik.h)
//   joint_pd           joint-space position / velocity / effort (control/joint_controller.h)
//   keyframe_playback  MJCF keys or CSV joint targets over time (control/keyframe_playback.h)
//   multirotor_pid     cascaded multirotor flight controller (control/multirotor_pid.h)
//   policy             a learned ONNX policy on observation terms (control/policy_controller.h)
//   trot_gait          model-based trot gait for 12-DoF quadrupeds (control/trot_gait.h)
//   waypoint_follower  differential-drive waypoint follower (control/waypoint_follower.h)

#include <memory>
#include <string>
#include <vector>

#include "penumbra/control/controller.h"
#include "penumbra/control/controller_config.h"

namespace penumbra {

/// the controller described by `cfg` for robot `robot_name`, or nullptr when cfg.type is
/// empty. robot-local model names in the parameters get the "<robot_name>/" prefix (none
/// when robot_name is empty), matching the composer's naming. the result still has to be
/// initialised against the model (Simulation::AddController does that).
/// @throws ConfigError(world_file, cfg.line, "robots[<robot>].controller.<key>", ...) for an
///         unknown type, params that are not a mapping, unknown keys, missing keys or bad
///         values ("controller.<key>" when robot_name is empty).
std::unique_ptr<Controller> MakeController(const ControllerConfig& cfg,
                                           const std::string& robot_name,
                                           const std::string& world_file);

/// the controller types MakeController knows, sorted.
std::vector<std::string> ControllerTypes();

}  // namespace penumbra
