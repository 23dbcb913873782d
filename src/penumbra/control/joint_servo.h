#pragma once
// the joint-space servo shared by the joint controllers (joint_pd, diff_ik,
// keyframe_playback): it turns a joint reference (position, velocity, feed-forward effort)
// into the ctrl of one actuator per joint, within position, velocity and effort limits.
//
// world-file keys it reads (inside the controller block; names are robot-local):
//   joints: [joint1, ..., joint7]          # hinge or slide joints, in the controller's order
//   actuators: [actuator1, ..., actuator7] # one per joint, each driving that joint
//   output: torque         # torque: motor actuators, ctrl = effort / gear (N m or N); any
//                          # other actuator (a position servo, ...) is refused at Initialize
//                          # position: position servos, ctrl = gear * position reference
//   kp: 600                # N m/rad (N/m), one number or one per joint (torque output)
//   kd: 50                 # N m s/rad (N s/m), one number or one per joint (torque output)
//   gravity_compensation: true   # add MuJoCo's qfrc_bias (torque output)
//   max_velocity: 2.0      # rad/s (m/s), > 0, one or per joint: the reference moves no faster
//   max_acceleration: 10   # rad/s^2 (m/s^2), > 0, one or per joint: position references
//                          # speed up and slow down no harder (StepTowards)
//   max_effort: 87         # N m (N), > 0, one or per joint (default: the actuator's ctrlrange x
//   gear) limit_margin: 0.01     # rad (m) >= 0: position references stay this far inside joint
//   ranges
//
// control law (torque output), per joint i, with reference (q_r, qd_r, tau_ff):
//   tau_i = kp_i (q_r,i - q_i) + kd_i (qd_r,i - qd_i) + tau_ff,i [+ qfrc_bias_i]
//   clamped to [-max_effort_i, max_effort_i]; ctrl_i = tau_i / gear_i.
// a joint-space PD with gravity/Coriolis feed-forward ("PD plus gravity compensation",
// Takegaki and Arimoto, ASME J. Dyn. Syst. Meas. Control 103(2), 1981; computed-torque
// feed-forward as in Siciliano et al., "Robotics: Modelling, Planning and Control",
// Springer 2009, sec. 8.5). position output writes ctrl_i = gear_i q_r,i and leaves the
// loop to the MuJoCo position servo.

#include <Eigen/Core>
#include <span>
#include <string>
#include <vector>

#include "penumbra/control/controller.h"
#include "penumbra/control/controller_params.h"

namespace penumbra {

/// what the servo's actuators take as ctrl.
enum class ServoOutput {
  kTorque,    ///< motor actuators: ctrl = effort / gear
  kPosition,  ///< position servos: ctrl = gear * position reference
};

/// parameters of a JointServo (see the file comment for keys and ranges).
struct JointServoParams {
  std::vector<std::string> joints;     ///< full model names
  std::vector<std::string> actuators;  ///< full model names, actuators[i] drives joints[i]
  ServoOutput output = ServoOutput::kTorque;
  std::vector<double> kp;                ///< (n) N m/rad or N/m
  std::vector<double> kd;                ///< (n) N m s/rad or N s/m
  bool gravity_compensation = true;      ///< torque output: add qfrc_bias
  std::vector<double> max_velocity;      ///< (n) rad/s or m/s
  std::vector<double> max_acceleration;  ///< (n) rad/s^2 or m/s^2
  std::vector<double> max_effort;        ///< (n) N m or N; empty = from the actuators' ctrlrange
  double limit_margin = 0.01;            ///< rad or m

  /// reads the keys of the file comment; names get `name_prefix`. `default_kp`, `default_kd`,
  /// `default_max_velocity` and `default_max_acceleration` apply when a key is absent
  /// (negative: the key is required).
  /// @throws ConfigError for missing/bad keys and joints/actuators lists of unequal length.
  static JointServoParams Parse(ControllerParams& params, const std::string& name_prefix,
                                double default_kp = -1, double default_kd = -1,
                                double default_max_velocity = 2.0,
                                double default_max_acceleration = 10.0);
  /// @throws ConfigError (in `context`) for sizes that disagree or values out of range.
  void ValidateOrThrow(const ControllerContext& context) const;
};

/// joint-space servo over n joints (see the file comment). not thread-safe.
class JointServo {
 public:
  /// @throws ConfigError if `params` are inconsistent.
  JointServo(JointServoParams params, const ControllerContext& context);

  /// appends the joints (keys "joints[i]") and actuators ("actuators[i]") to `reqs`.
  void AppendRequiredNames(std::vector<NameRequirement>* reqs) const;
  /// binds the servo to the model; `ids` are the resolved ids of the names appended by
  /// AppendRequiredNames, in the same order.
  /// @throws ConfigError if a joint is not a hinge/slide, an actuator does not drive its
  ///         joint, or a gear is zero.
  void Bind(const ModelInfo& model, std::span<const int> ids, const ControllerContext& context);

  int size() const { return static_cast<int>(params_.joints.size()); }
  const JointServoParams& params() const { return params_; }
  /// (n) lower / upper bounds for position references: the joint range shrunk by
  /// limit_margin (+-infinity for unlimited joints). valid after Bind.
  const Eigen::VectorXd& q_min() const { return q_min_; }
  const Eigen::VectorXd& q_max() const { return q_max_; }
  /// (n) velocity limits (rad/s or m/s).
  const Eigen::VectorXd& qd_max() const { return qd_max_; }
  /// (n) qvel index of each joint (for Jacobian columns). valid after Bind.
  const std::vector<int>& dof_adr() const { return dof_adr_; }

  /// (n) current positions and velocities of the servo's joints.
  void ReadState(const ControlInput& input, Eigen::VectorXd* q, Eigen::VectorXd* qd) const;
  /// `q` clamped into [q_min, q_max].
  Eigen::VectorXd ClampPosition(const Eigen::VectorXd& q) const;
  /// moves the reference `q_ref` one step of `dt` towards `target` (clamped into the
  /// ranges) along a straight line in joint space, and sets `qd_ref` to the step / dt.
  /// per joint i the speed is at most
  ///   min(max_velocity_i, |qd_ref_i| + max_acceleration_i dt,
  ///       |target_velocity_i| + v_brake(|distance left_i|)),
  /// with v_brake(d) = a dt (sqrt(1/4 + 2 d / (a dt^2)) - 1/2), the speed from which steps
  /// slowing by a dt each stop within d (sqrt(2 a d) as dt -> 0):
  /// a trapezoidal profile that speeds up and brakes within the limits, and that follows a
  /// target moving at target_velocity ((n), or empty for a fixed target) without lag when
  /// the target's own motion is within the limits. one factor scales all joints, so they
  /// arrive together and the reference never passes the target. dt <= 0 leaves q_ref and
  /// zeroes qd_ref.
  void StepTowards(const Eigen::VectorXd& target, const Eigen::VectorXd& target_velocity, double dt,
                   Eigen::VectorXd* q_ref, Eigen::VectorXd* qd_ref) const;

  /// writes the servo's actuators in `ctrl` for the reference (q_ref, qd_ref) with
  /// feed-forward effort `tau_ff` ((n) each); `tau_ff` may be empty (zero).
  /// @throws Error if gravity compensation is on and `input` provides no qfrc_bias.
  void Write(const ControlInput& input, const Eigen::VectorXd& q_ref, const Eigen::VectorXd& qd_ref,
             const Eigen::VectorXd& tau_ff, std::span<double> ctrl) const;
  /// torque output only: writes effort `tau` ((n), plus qfrc_bias when gravity compensation
  /// is on), clamped to max_effort.
  void WriteEffort(const ControlInput& input, const Eigen::VectorXd& tau,
                   std::span<double> ctrl) const;
  /// the efforts (N m or N) of the last Write/WriteEffort, after clamping; empty before.
  const Eigen::VectorXd& last_effort() const { return last_effort_; }

 private:
  double Bias(const ControlInput& input, int i) const;

  JointServoParams params_;
  std::vector<int> qpos_adr_, dof_adr_, actuator_;
  std::vector<double> gear_;
  Eigen::VectorXd q_min_, q_max_, qd_max_, effort_max_;
  mutable Eigen::VectorXd delta_;
  mutable Eigen::VectorXd last_effort_;
};

}  // namespace penumbra
