#pragma once
// observation and action conventions of the training frameworks users bring policies from, as
// presets of the policy controller (`preset:` key, control/policy_controller.h). each preset
// is the framework's base velocity-tracking task in its play (deployment) configuration:
// observation noise off, as legged_gym's play.py (add_noise = False), Isaac Lab's *_PLAY
// configs and mjlab's play mode (enable_corruption = False) run it. the robot-specific parts
// (joint order, default joint positions, PD gains, a robot's own action scale) are not in a
// preset: the world file gives them. docs/policies.md cites the source file and commit of each.
//
//   legged_gym        legged_gym/envs/base/legged_robot.py compute_observations() with
//                     legged_robot_config.py's normalization: base_lin_vel x2, base_ang_vel
//                     x0.25, projected_gravity, velocity_command x(2, 2, 0.25), joint_pos,
//                     joint_vel x0.05, last_action; every term clipped to +-100
//                     (clip_observations); action joint_position, scale 0.5, clip 100
//                     (clip_actions); 50 Hz (sim dt 0.005 s, decimation 4). 48 values for
//                     12 joints.
//   legged_gym_rough  legged_gym plus height_scan: 17 x 11 points over x -0.8 .. 0.8, y -0.5 ..
//                     0.5 (measured_points_x / _y), y fastest (torch.meshgrid(x, y)),
//                     root z - 0.5 - height, x5 (height_measurements), clip +-5 (the source
//                     clips to +-1 before scaling). 235 values.
//   isaac_lab         isaaclab_tasks locomotion/velocity/velocity_env_cfg.py ObservationsCfg
//                     PolicyCfg: base_lin_vel, base_ang_vel, projected_gravity,
//                     velocity_command, joint_pos (rel), joint_vel (rel), last_action, all
//                     unscaled; action joint_position (JointPositionActionCfg, scale 0.5,
//                     use_default_offset); 50 Hz (sim dt 0.005 s, decimation 4).
//   isaac_lab_rough   isaac_lab plus height_scan: GridPatternCfg(resolution 0.1, size
//                     [1.6, 1.0]), ordering "xy" (x fastest), offset 0.5, clip +-1.
//   mjlab             mjlab/tasks/velocity/velocity_env_cfg.py actor terms: base_lin_vel,
//                     base_ang_vel, projected_gravity, joint_pos, joint_vel, last_action,
//                     velocity_command (its flat variant: no height scan); action
//                     joint_position (JointPositionActionCfg scale 0.5, use_default_offset);
//                     50 Hz (timestep 0.005 s, decimation 4).

#include <optional>
#include <string>
#include <vector>

#include "penumbra/control/policy_action.h"
#include "penumbra/control/policy_observation.h"

namespace penumbra {

/// the framework conventions (see the file comment).
enum class PolicyConvention { kLeggedGym, kLeggedGymRough, kIsaacLab, kIsaacLabRough, kMjlab };

/// what a preset fills in.
struct PolicyPreset {
  std::vector<ObservationTermConfig> observations;
  PolicyActionParams action;
  double rate_hz = 50;
};

/// the world-file name of a convention ("legged_gym", ...).
const char* PolicyConventionName(PolicyConvention convention);
/// the convention named `name`, or nullopt.
std::optional<PolicyConvention> PolicyConventionFromName(const std::string& name);
/// every preset name, comma-separated (for messages).
std::string PolicyConventionNames();
/// the preset of `convention`.
PolicyPreset MakePolicyPreset(PolicyConvention convention);

}  // namespace penumbra
