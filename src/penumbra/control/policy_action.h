#pragma once
// how a learned policy's output becomes actuator commands (control/policy_controller.h).
// world-file form (inside the policy controller block):
//   action:
//     type: joint_position   # joint_position | joint_velocity | joint_torque
//     scale: 0.25            # one number or one per joint, |scale| <= 1e4
//     clip: 100              # 0 < clip <= 1e6: the raw output is clamped to [-clip, clip]
//                            # first (optional)
//     kp: 20                 # N m/rad (N/m), one or per joint: PD through any actuator
//     kd: 0.5                # N m s/rad (N s/m), one or per joint
//     actuators: [FR_hip, ...]   # one per policy joint (default: the joint names)
//
// with a the raw output (clamped by clip) and j a policy joint:
//   joint_position  q*_j = q_default,j + scale_j a_j (the offset is the default pose).
//                   with kp: tau_j = kp_j (q*_j - q_j) - kd_j qdot_j at every physics step
//                   (legged_gym's "P" control, its _compute_torques), applied through the
//                   joint's actuator by its force law (control/actuator_drive.h: motors,
//                   position or velocity servos). without kp: the actuators must be position
//                   servos (MJCF <position>) and get ctrl = gear q*_j (the servo closes the
//                   loop, as Isaac Lab's implicit actuators and mjlab's position actuators do).
//   joint_velocity  qd*_j = scale_j a_j. with kd: tau_j = kd_j (qd*_j - qdot_j) through the
//                   actuator; without: velocity servos (MJCF <velocity>), ctrl = gear qd*_j.
//   joint_torque    tau_j = scale_j a_j through the actuator (kp, kd not allowed).
// every ctrl is clamped to the actuator's forcerange / ctrlrange (control/actuator_drive.h).
// a raw output that is not finite or exceeds kPolicyMaxAbsAction in magnitude stops the run
// (ProcessPolicyOutputs), naming the policy step and the output.

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "penumbra/config/config_value.h"
#include "penumbra/control/controller_params.h"

namespace penumbra {

/// the largest |raw output| a policy may return (before its clip): a network whose output
/// reaches it (or is not finite) is broken, and the run stops naming the step and output.
inline constexpr double kPolicyMaxAbsAction = 1e6;
/// the largest |scale| of an action (rad, rad/s or N m per output unit), checked at load.
inline constexpr double kPolicyMaxActionScale = 1e4;

/// what the policy's outputs are.
enum class PolicyActionKind { kJointPosition, kJointVelocity, kJointTorque };

/// the world-file name of an action kind ("joint_position", ...).
const char* PolicyActionKindName(PolicyActionKind kind);

/// the `action:` block (see the file comment).
struct PolicyActionParams {
  PolicyActionKind kind = PolicyActionKind::kJointPosition;
  std::vector<double> scale = {1.0};   ///< 1 value or one per joint
  std::optional<double> clip;          ///< > 0
  std::vector<double> kp, kd;          ///< empty = servo actuators; else 1 value or per joint
  std::vector<std::string> actuators;  ///< full names, one per joint; empty = joint names

  /// overrides the fields present in the mapping `node` (key path `key`); actuator names get
  /// `name_prefix`.
  /// @throws ConfigError naming key.<field> for unknown fields and bad values.
  void ParseOver(ControllerParams& params, const ConfigValue& node, const std::string& key,
                 const std::string& name_prefix);
};

/// checks and clips one policy update's raw outputs: `action[j]` = `raw[j]` clamped to
/// [-clip, clip] when `clip` is set. `step` (the policy update's physics step), `time_sec` and
/// `joints` (names, one per output) only name the failure.
/// @throws Error "<label>: policy step <step> (t = <time> s): output <j> (joint '<name>') is
///         <value>; expected a finite value with |value| <= kPolicyMaxAbsAction" for the first
///         non-finite or too large output; `action` is then partly written.
void ProcessPolicyOutputs(std::span<const float> raw, const std::optional<double>& clip,
                          int64_t step, double time_sec, const std::vector<std::string>& joints,
                          const std::string& label, std::span<double> action);

}  // namespace penumbra
