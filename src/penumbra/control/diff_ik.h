#pragma once
// diff_ik: Cartesian control of an arm by differential inverse kinematics. the pose of an
// end-effector site follows Cartesian targets (jumps, or straight-line moves at a given
// speed); damped least squares on MuJoCo's site Jacobian turns the task velocity into joint
// velocities, which integrate into a joint position reference for the joint servo
// (control/joint_servo.h). an optional gripper actuator opens and closes on command.
//
// world-file block (robot-local names get the "<robot>/" prefix):
//   controller:
//     type: diff_ik
//     site: ee                  # end-effector site (its pose is what the targets set)
//     base_body: link0          # targets are poses of the site in this body's frame
//                               # (default: the world frame)
//     joints: [...]             # JointServo keys (joint_servo.h): joints, actuators, output,
//     actuators: [...]          # kp, kd, gravity_compensation, max_velocity, max_effort,
//                               # limit_margin (default 0.01 rad)
//     position_gain: 10         # 1/s, > 0: K_p of the Cartesian error feedback
//     orientation_gain: 10      # 1/s, > 0: K_o
//     damping: 0.01             # lambda_min >= 0 of the damped least squares
//     damping_max: 0.1          # lambda_max >= damping, reached at singularities
//     manipulability_threshold: 0.005  # w_0 > 0 below which damping grows
//     max_linear_speed_m_s: 1.0        # > 0, clamp of the commanded task velocity
//     max_angular_speed_deg_s: 180     # > 0
//     speed_m_s: 0.25                  # > 0, default peak speed of move_to / move_by
//     angular_speed_deg_s: 90          # > 0, default peak angular speed
//     posture: [...]            # null-space posture (rad or m, one per joint); default: the
//                               # configuration at the first update
//     posture_gain: 0.3         # 1/s >= 0
//     limit_zone: 0.2           # rad (m) > 0: the limit-avoidance gradient acts this close
//                               # to the (margin-shrunk) joint ranges
//     limit_gain: 5.0           # 1/s >= 0
//     limit_velocity_gain: 5    # 1/s > 0: speed towards a range bound <= this x distance
//     max_tracking_error: 0.2   # rad (m) > 0: the reference stays this close to the joints
//     gripper_actuator: gripper # optional actuator; ctrl = gripper_open / gripper_closed
//     gripper_open: 0.04        # default: the actuator's ctrlrange maximum
//     gripper_closed: 0.0       # default: the actuator's ctrlrange minimum
//     gripper_initial: open     # open | close | a ctrl value (default open)
//     commands:                 # timed commands (control/command_script.h), one verb each:
//       - {t: 0.0, move_to: {xyz: [0.5, 0, 0.3], rpy_deg: [180, 0, 0]}, speed_m_s: 0.2}
//       - {t: 2.0, move_by: {xyz: [0, 0, -0.1]}}     # relative to the current target
//       - {t: 3.0, pose: {xyz: [0.5, 0, 0.2], rpy_deg: [180, 0, 0]}}  # jump the target
//       - {t: 4.0, gripper: close}                   # open | close | ctrl value
//     rate_hz: 0                # control rate on sim time; 0 = every physics step
//   move_to / move_by take optional speed_m_s and angular_speed_deg_s; rpy_deg defaults to
//   the current target's orientation (move_to) or no rotation (move_by).
//
// frames: poses are X_BT, the target frame T of the site in the base frame B (translation
// in m, roll/pitch/yaw in degrees, REP-103 extrinsic x-y-z). move_by rotates the target
// about the base axes through the site: R_new = R(rpy) R_old, p_new = p_old + xyz.
//
// law, at each update (time t, dt since the previous update), with the joint positions q,
// the site pose (p, R) and its Jacobian J (6 x n, rows angular then linear, world frame,
// columns of the controlled joints; MuJoCo mj_jac through ControlInput::Jacobian):
//   1. target (p_d, R_d) and feed-forward twist (w_d, v_d) from the active move. straight
//      moves interpolate p_d linearly and R_d by slerp (K. Shoemake, SIGGRAPH 1985) with the
//      minimum-jerk time scaling s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5 (Flash and Hogan,
//      J. Neurosci. 5(7), 1985); the duration T = 1.875 max(|dp| / speed, angle / angular
//      speed) makes the peak speed the requested one.
//   2. task velocity x_dot = [w_d + K_o log(R_d R^T); v_d + K_p (p_d - p)], each part
//      clamped to the max speeds (closed-loop inverse kinematics, Siciliano et al.,
//      "Robotics: Modelling, Planning and Control", 2009, sec. 3.7).
//   3. damped least squares (C. W. Wampler, IEEE SMC 16(1), 1986; Y. Nakamura and H.
//      Hanafusa, J. Dyn. Syst. Meas. Control 108(3), 1986; survey: S. R. Buss, "Introduction
//      to inverse kinematics with Jacobian transpose, pseudoinverse and damped least
//      squares methods", 2004): J# = J^T (J J^T + lambda^2 I)^-1 with the
//      manipulability w = sqrt(det(J J^T)) and
//      lambda^2 = damping^2 + (damping_max^2 - damping^2) (1 - w / w_0)^2 when w < w_0.
//   4. null space: qdot = J# x_dot + (I - J# J) z, z = posture_gain (q_posture - q_r) +
//      limit_gain g(q_r), where g pushes joints out of the limit zone (g_i = q_min,i +
//      zone - q_r,i below it, q_max,i - zone - q_r,i above it, else 0): the gradient
//      projection method (A. Liegeois, IEEE SMC 7(12), 1977).
//   5. joint limits by clamping: a joint whose velocity towards a bound of [q_min, q_max]
//      exceeds limit_velocity_gain times the distance left (a velocity damper, B. Faverjon
//      and P. Tournassoud, IEEE ICRA 1987; it also never crosses the bound within a step)
//      is held at that velocity, its Jacobian column removed and the rest re-solved for the
//      remaining task (clamping, P. Baerlocher and R. Boulic, The Visual Computer 20,
//      2004); repeated until no joint exceeds its bound.
//   6. qdot scaled by one factor so that |qdot_i| <= max_velocity_i; q_r += qdot dt,
//      clamped into the ranges and to within max_tracking_error of q; the servo tracks
//      (q_r, qdot) with gravity compensation.
// the reference integrates the Cartesian error measured at the real joints, so loads and
// servo errors are corrected and the steady-state pose error goes to zero.

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "penumbra/control/command_script.h"
#include "penumbra/control/controller.h"
#include "penumbra/control/controller_params.h"
#include "penumbra/control/joint_servo.h"
#include "penumbra/core/pose.h"

namespace penumbra {

/// a diff_ik command.
struct ArmCommand {
  enum class Kind {
    kMoveTo,   ///< straight-line move to pose (in the base frame)
    kMoveBy,   ///< straight-line move by a translation and rotation from the current target
    kPose,     ///< set the target to pose at once
    kGripper,  ///< gripper action
  };
  enum class GripperAction { kOpen, kClose, kValue };

  Kind kind = Kind::kPose;
  /// kMoveTo, kPose: X_BT, the target of the site in the base frame. kMoveBy: the
  /// translation (m, base frame) and rotation (about the base axes) to apply.
  Pose pose = Pose::Identity();
  /// kMoveTo: false = keep the current target's orientation.
  bool has_orientation = true;
  double speed_m_s = 0;            ///< kMoveTo/kMoveBy peak linear speed; 0 = default
  double angular_speed_rad_s = 0;  ///< kMoveTo/kMoveBy peak angular speed; 0 = default
  GripperAction gripper = GripperAction::kOpen;
  double gripper_value = 0;  ///< kValue: the ctrl to write

  static ArmCommand MoveTo(const Pose& X_BT, double speed_m_s = 0, double angular_speed_rad_s = 0);
  static ArmCommand MoveBy(const Pose& delta, double speed_m_s = 0, double angular_speed_rad_s = 0);
  static ArmCommand SetPose(const Pose& X_BT);
  static ArmCommand Gripper(GripperAction action, double value = 0);
};

/// parameters of a DiffIkController (see the file comment for keys, meanings and ranges).
struct DiffIkParams {
  JointServoParams servo;
  std::string site;       ///< full model name
  std::string base_body;  ///< full model name, "" = world
  double position_gain = 10;
  double orientation_gain = 10;
  double damping = 0.01;
  double damping_max = 0.1;
  double manipulability_threshold = 0.005;
  double max_linear_speed_m_s = 1.0;
  double max_angular_speed_rad_s = M_PI;
  double speed_m_s = 0.25;
  double angular_speed_rad_s = M_PI / 2;
  std::optional<std::vector<double>> posture;
  double posture_gain = 0.3;
  double limit_zone = 0.2;
  double limit_gain = 5.0;
  double max_tracking_error = 0.2;
  double limit_velocity_gain = 5;
  std::string gripper_actuator;  ///< full model name, "" = none
  std::optional<double> gripper_open, gripper_closed;
  ArmCommand gripper_initial = ArmCommand::Gripper(ArmCommand::GripperAction::kOpen);
  std::vector<TimedCommand<ArmCommand>> commands;
  double rate_hz = 0;

  /// @throws ConfigError for missing/unknown keys and bad values.
  static DiffIkParams Parse(ControllerParams& params, const std::string& name_prefix);
  /// @throws ConfigError (in `context`) for values out of range.
  void ValidateOrThrow(const ControllerContext& context) const;
};

/// differential inverse kinematics controller (see the file comment). Compute runs on the
/// physics thread; PushCommand / SetCommand may be called from any thread.
class DiffIkController final : public Controller {
 public:
  /// @throws ConfigError if `params` are out of range.
  DiffIkController(DiffIkParams params, ControllerContext context);

  std::string type() const override { return "diff_ik"; }
  double rate_hz() const override { return params_.rate_hz; }
  std::vector<NameRequirement> RequiredNames() const override;
  void Compute(const ControlInput& input, std::span<double> ctrl) override;
  /// forgets the queued commands, the move in progress, the target and the posture
  /// (the next update takes the start pose again); the script starts over.
  void Reset() override;

  /// queues `command` for the update at or after `at_time_sec` (default: the next one).
  /// thread-safe. @throws Error for a gripper command without gripper_actuator, or
  ///         non-finite values.
  void PushCommand(ArmCommand command,
                   double at_time_sec = -std::numeric_limits<double>::infinity());
  /// replaces every queued command by `command`. thread-safe; throws as PushCommand.
  void SetCommand(ArmCommand command);

  const DiffIkParams& params() const { return params_; }
  const JointServo& servo() const { return servo_; }

  // state of the last update (physics thread):
  /// X_BT of the target at the end of the active move (or the jump target).
  const Pose& goal() const { return X_BG_; }
  /// X_BT of the target at the last update (on the way along a move).
  const Pose& target() const { return X_BT_; }
  /// true while a straight-line move is under way.
  bool moving() const { return moving_; }
  /// |p_d - p| (m) and the angle of R_d R^T (rad) at the last update.
  double position_error_m() const { return position_error_; }
  double orientation_error_rad() const { return orientation_error_; }
  /// (n) joint position reference and velocity of the last update.
  const Eigen::VectorXd& q_ref() const { return q_ref_; }
  const Eigen::VectorXd& qd_ref() const { return qdot_; }
  /// the gripper ctrl being written (when there is a gripper actuator).
  double gripper_ctrl() const { return gripper_ctrl_; }
  /// manipulability sqrt(det(J J^T)) and lambda of the last update.
  double manipulability() const { return manipulability_; }
  double lambda() const { return lambda_; }

 protected:
  void OnInitialize(const ModelInfo& model, const std::vector<int>& ids) override;

 private:
  void CheckCommand(const ArmCommand& c) const;
  void Apply(const ArmCommand& c, double t);
  void StartMove(const Pose& X_BG, double speed, double angular_speed, double t);
  void UpdateTarget(double t);
  void SolveDls(double dt);

  DiffIkParams params_;
  JointServo servo_;
  CommandSource<ArmCommand> commands_;
  int site_body_ = -1, base_body_ = -1, gripper_ = -1;
  Pose X_bodysite_ = Pose::Identity();
  double gripper_open_ = 0, gripper_closed_ = 0, gripper_ctrl_ = 0;

  bool started_ = false;
  double last_time_ = 0;
  // move state (base frame)
  bool moving_ = false;
  Pose X_BS0_ = Pose::Identity();                      // start of the move
  Pose X_BG_ = Pose::Identity();                       // goal
  Pose X_BT_ = Pose::Identity();                       // current target
  Eigen::Vector3d axis_S_ = Eigen::Vector3d::UnitX();  // rotation axis, in the start frame
  double angle_ = 0, t0_ = 0, duration_ = 0;
  Eigen::Matrix<double, 6, 1> twist_ff_B_ = Eigen::Matrix<double, 6, 1>::Zero();

  double position_error_ = 0, orientation_error_ = 0, manipulability_ = 0, lambda_ = 0;
  Eigen::VectorXd q_, qd_, q_ref_, qdot_, posture_, z_, dq_fixed_, tmp_n_;
  std::vector<char> clamped_;
  Eigen::Matrix<double, 6, Eigen::Dynamic> J_full_, J_, Ja_;
  Eigen::Matrix<double, 6, 1> xdot_;
  Eigen::LLT<Eigen::Matrix<double, 6, 6>> llt_;
};

}  // namespace penumbra
