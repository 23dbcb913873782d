#pragma once
// joint_pd: joint-space control of a set of joints in one of three modes, switched by
// commands: position (PD to a target), velocity (the reference integrates a commanded
// velocity) or effort (torque/force straight through). the law and the limits are those of
// control/joint_servo.h.
//
// world-file block (robot-local names get the "<robot>/" prefix):
//   controller:
//     type: joint_pd
//     joints: [joint1, joint2]         # the JointServo keys (joint_servo.h): joints,
//     actuators: [actuator1, actuator2]  # actuators, output, kp, kd, gravity_compensation,
//     kp: [600, 600]                   # max_velocity, max_effort, limit_margin
//     kd: [50, 50]                     # (max_acceleration: 10 rad/s^2 by default)
//     target: [0.0, -0.5]              # initial position target (rad or m); default: the
//                                      # configuration at the first update (hold still)
//     commands:                        # timed commands (control/command_script.h), each with
//       - {t: 1.0, q: [0.5, -0.2]}     # exactly one of q (position target), qd (velocity,
//       - {t: 3.0, qd: [0.2, 0.0]}     # rad/s or m/s) or tau (effort, N m or N; torque
//       - {t: 5.0, tau: [0.0, 1.0]}    # output only)
//     rate_hz: 0                       # control rate on sim time; 0 = every physics step
//
// reference generation, at each update with dt = time since the previous update:
//   position: the reference q_r moves towards the target along a straight line in joint
//     space with a trapezoidal velocity profile within max_velocity and max_acceleration
//     (JointServo::StepTowards; all joints scaled by one factor so they arrive together);
//     qd_r = (q_r,new - q_r,old) / dt. targets are clamped into the joint ranges shrunk
//     by limit_margin.
//   velocity: qd_r = the commanded velocity clamped to +-max_velocity; q_r integrates it
//     (over each interval, the velocity commanded during that interval), stopping
//     (qd_r = 0) at the range bounds.
//   effort: tau = command (+ qfrc_bias with gravity_compensation), clamped to max_effort.
// switching to position or velocity from effort restarts the reference at the measured q.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "penumbra/control/command_script.h"
#include "penumbra/control/controller.h"
#include "penumbra/control/controller_capabilities.h"
#include "penumbra/control/controller_params.h"
#include "penumbra/control/joint_servo.h"

namespace penumbra {

// JointCommand and the JointTarget interface: control/controller_capabilities.h.

/// parameters of a JointPdController (see the file comment).
struct JointPdParams {
  JointServoParams servo;
  std::optional<std::vector<double>> target;  ///< (n) initial position target
  std::vector<TimedCommand<JointCommand>> commands;
  double rate_hz = 0;

  /// @throws ConfigError for missing/unknown keys and bad values.
  static JointPdParams Parse(ControllerParams& params, const std::string& name_prefix);
  /// @throws ConfigError (in `context`) for sizes or values out of range, or effort commands
  ///         with position output.
  void ValidateOrThrow(const ControllerContext& context) const;
};

/// joint-space PD / velocity / effort controller (see the file comment).
class JointPdController final : public Controller, public JointTarget {
 public:
  /// @throws ConfigError if `params` are inconsistent.
  JointPdController(JointPdParams params, ControllerContext context);

  std::string type() const override { return "joint_pd"; }
  double rate_hz() const override { return params_.rate_hz; }
  std::vector<NameRequirement> RequiredNames() const override;
  void Compute(const ControlInput& input, std::span<double> ctrl) override;
  /// forgets the queued commands, the command in force and the reference (the next update
  /// holds the start pose or `target` again); the script starts over.
  void Reset() override;

  /// queues `command` for the update at or after `at_time_sec` (default: the next one).
  /// thread-safe. @throws Error if its size is not the number of joints, a value is not
  /// finite, or it is an effort command and the output is position.
  void PushCommand(JointCommand command,
                   double at_time_sec = -std::numeric_limits<double>::infinity());
  /// replaces every queued command by `command` (latest wins). thread-safe; throws as
  /// PushCommand.
  void SetCommand(JointCommand command) override;
  /// the joints of the command vectors (params().servo.joints).
  const std::vector<std::string>& command_joints() const override { return params_.servo.joints; }

  const JointPdParams& params() const { return params_; }
  /// the active mode and its command values (physics thread).
  const JointCommand& active_command() const { return active_; }
  /// (n) the position reference of the last update (physics thread).
  const Eigen::VectorXd& q_ref() const { return q_ref_; }
  const JointServo& servo() const { return servo_; }

 protected:
  void OnInitialize(const ModelInfo& model, const std::vector<int>& ids) override;

 private:
  void CheckCommand(const JointCommand& c) const;
  void Apply(const JointCommand& c, const Eigen::VectorXd& q);

  JointPdParams params_;
  JointServo servo_;
  CommandSource<JointCommand> commands_;
  JointCommand active_;
  bool started_ = false;
  double last_time_ = 0;
  Eigen::VectorXd q_, qd_, q_ref_, qd_ref_, target_, values_;
};

}  // namespace penumbra
