#pragma once
// model-based trot gait for 12-DoF quadrupeds (three-joint legs FR, FL, RR, RL) following
// a twist command (vx, vy forward/left in the heading frame, m/s; yaw rate, rad/s).
//
// world-file block (robot-local names get the "<robot>/" prefix):
//   controller:
//     type: trot_gait
//     base_body: trunk              # the floating base; its subtree is the robot
//     legs:                          # exactly FR, FL, RR, RL
//       FR: {hip: FR_hip, thigh: FR_thigh, calf: FR_calf, foot: FR_foot,
//            signs: [1, 1, 1],         # model joint direction vs the canonical one (+-1)
//            offsets_rad: [0, 0, 0],   # q_canonical = sign q_model + offset (default 0)
//            actuators: [FR_hip, FR_thigh, FR_calf]}  # motors or position/velocity servos
//                                                     # (default: the joint names)
//       FL: {...}
//       RR: {...}
//       RL: {...}
//     commands:                      # scripted twist, held from each t (s) to the next
//       - {t: 0, vx: 0, vy: 0, yaw_rate: 0}
//       - {t: 1, vx: 0.5}            # missing components are 0
//     waypoints: [[1, 0], [1, 1]]    # waypoint mode: world x, y (m) of the base body's
//                                    # origin, at least 1 (the next four keys only with it)
//     loop: true                     # after the last waypoint, start again (default true)
//     speed_m_s: 0.5                 # > 0, cruise speed along the route (default 0.5)
//     max_yaw_rate_deg_s: 60         # > 0, yaw-rate limit of the route (default 60)
//     tolerance_m: 0.15              # > 0, a waypoint counts as reached inside this
//                                    # radius (default 0.15)
//     period_sec: 0.36               # gait cycle (> 0, default 0.36)
//     duty: 0.5                      # stance fraction of the cycle (0.3 .. 0.8, default 0.5)
//     swing_height_m: 0.08           # apex of the foot above the line lift-off -> touch-down
//     body_height_m: 0.25            # COM above the plane of the stance feet's centres
//                                    # (default: the height at the first update, at least
//                                    # 0.3 (l2 + l3))
//     raibert_gain: 0.17             # k of the velocity feedback (s; default sqrt(h / g))
//     max_step_m: 0.17               # |touch-down - nominal| limit (default 0.4 (l2 + l3))
//     max_accel_m_s2: 1.5            # command slew limits (defaults 1.5 and 3)
//     max_yaw_accel_rad_s2: 3
//     kp_xy: 25, kd_xy: 8            # COM position/velocity gains (1/s^2, 1/s)
//     kp_z: 400, kd_z: 40            # height gains (1/s^2, 1/s)
//     kp_tilt: 400, kd_tilt: 40      # roll/pitch gains (1/s^2, 1/s)
//     kp_yaw: 150, kd_yaw: 25        # yaw gains (1/s^2, 1/s)
//     swing_kp: 60, swing_kd: 1.5    # swing-leg joint PD (N m/rad, N m s/rad)
//     stance_kd: 0.5                 # stance-leg joint damping (N m s/rad)
//     friction: 0.6                  # friction coefficient assumed for the force cones
//     hold: {arm_joint2: 1.2}        # other actuators held at a constant ctrl (optional)
//     rate_hz: 250                   # control rate on sim time (default 250: every 2nd 2 ms step)
// the gains in 1/s^2 and 1/s multiply the robot's mass (kg) and its composite rotational
// inertia at qpos0 (kg m^2), both taken from the model, so one set suits robots of any size.
//
// kinematics: the canonical leg convention of control/quadruped_leg_kinematics.h. hip
// offsets, abduction offsets and thigh lengths are read from the model at Initialize
// (joint anchors at body origins, as MJCF written from URDF has them): hip offset = the
// hip body's origin in the base frame, abduction offset = the thigh body's origin in the
// hip body frame (signed y-z distance), thigh length = |calf body origin| in the thigh
// frame, calf length = |foot site| in the calf frame. mass and COM come from the model's
// body masses (the base body's subtree); the COM is recomputed at each update.
//
// state: the base body's pose and twist (ground truth of the simulation, i.e. a perfect
// IMU + odometry estimator). the ground under the robot is a plane z = a + b x + c y
// fitted (least squares) to the last stance positions of the four feet.
//
// control law, at each update (time t, period T, duty D, T_st = D T, T_sw = T - T_st):
//   1. command, from the first source in force (precedence: programmatic > waypoints >
//      script):
//      a. the override from SetCommand(), until ClearCommand();
//      b. waypoint mode, while the route is not finished (a looping route never is): the
//         waypoint progress of control/waypoint_route.h (goal w; a waypoint within
//         tolerance_m of the base body's origin is reached), then the pure-pursuit law of
//         control/pure_pursuit.h, shared with waypoint_follower (R. C. Coulter,
//         CMU-RI-TR-92-01, 1992): vx = v, vy = 0, yaw_rate = omega, i.e. turn in place at
//         the yaw-rate limit while w lies more than 90 deg off the heading, else follow
//         the arc of curvature 2 sin(alpha) / |w - p| at speed_m_s, slowed until the
//         yaw rate is within the limit; the route only advances while it is in force;
//      c. the scripted entry with the largest t_i <= t (zero before the first and when
//         there is no script, i.e. trot in place). the reference twist (v_ref, w_ref)
//      follows it under the slew limits; the reference heading psi_ref and COM position
//      p_ref integrate it (v_ref rotated by the heading), both kept within 0.3 rad /
//      0.1 m of the robot (anti-windup, e.g. after a push).
//   2. gait: phase phi = t / T mod 1; FR and RL (one diagonal) have offset 0, FL and RR
//      offset 0.5; a leg with (phi - offset) mod 1 < D is in stance, else in swing.
//   3. stance: desired COM acceleration
//        a = kp_xy (p_ref - c)_xy + kd_xy (v_ref - v)_xy,
//        a_z = kp_z (h_ref - h) + kd_z (v_ref,z - v_z)  (h above the ground plane),
//      desired angular acceleration from the attitude error e = 1/2 (R^T R_ref -
//      R_ref^T R)^v in the base frame (T. Lee et al., "Geometric tracking control of a
//      quadrotor UAV on SE(3)", CDC 2010; R_ref: heading psi_ref, z axis along the ground
//      normal) with per-axis gains; wrench w = (m (a + g), I alpha) distributed over the
//      stance feet (control/quadruped_stance_forces.h); joint torques
//      tau = S J^T R^T (-f) - stance_kd qdot, with J the leg's analytic Jacobian at the
//      measured angles (control/quadruped_leg_kinematics.h; for a model in the canonical
//      convention it equals MuJoCo's translational Jacobian of the foot site, and it
//      costs a fraction of mj_jac) and S = diag(signs).
//   4. swing: touch-down point by the Raibert heuristic (M. H. Raibert, "Legged Robots
//      That Balance", MIT Press, 1986) with capture-point style velocity feedback
//      (J. Pratt et al., "Capture Point: A Step toward Humanoid Push Recovery", 2006):
//        p_td = p_hip(t_td) + v_ref T_st / 2 + k (v - v_ref) + (h / 2g) v x w_ref,
//      p_hip(t_td) the foot's nominal point (below the thigh axis) moved with the reference
//      twist until touch-down, |p_td - p_hip(t_td)| <= max_step_m, on the ground plane;
//      the foot follows a cycloid (control/quadruped_swing_trajectory.h) from its lift-off
//      point, tracked by joint PD on the analytic IK of the target, with the desired joint
//      velocity from the analytic leg Jacobian, plus MuJoCo's bias forces qfrc_bias
//      (gravity and velocity products) of the leg's joints as feed-forward:
//        tau = swing_kp (q_des - q) + swing_kd (qd_des - qd) + qfrc_bias.
//   5. each torque becomes its actuator's ctrl by the actuator's force law
//      (control/actuator_drive.h): motors ctrl = torque / (gear gain); position servos
//      (Menagerie's <position>) ctrl = gear q + (torque / gear + kv gear qdot) / kp; velocity
//      servos ctrl = gear qdot + torque / (gear kv); clamped to forcerange, then ctrlrange.
//      actuators with activation dynamics or other gain/bias laws are refused at
//      Initialize with an error naming the actuator and its type.
// sources for the whole scheme: the MIT Cheetah 3 balance controller (G. Bledt et al.,
// IROS 2018) and its convex-MPC successor (J. Di Carlo et al., IROS 2018), of which this is
// the QP-free variant.

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "penumbra/control/controller.h"
#include "penumbra/control/controller_params.h"
#include "penumbra/control/quadruped_leg_kinematics.h"
#include "penumbra/control/quadruped_stance_forces.h"
#include "penumbra/control/twist_command.h"
#include "penumbra/control/waypoint_route.h"

namespace penumbra {

/// names and sign conventions of one leg (full model names).
struct TrotLegConfig {
  std::string hip, thigh, calf;          ///< hinge joints
  std::string foot;                      ///< site at the foot point
  std::array<std::string, 3> actuators;  ///< motors or position/velocity servos (hip, thigh, calf)
  std::array<double, 3> signs = {1, 1, 1};        ///< +-1
  std::array<double, 3> offsets_rad = {0, 0, 0};  ///< q_canonical = sign q + offset
};

/// parameters of a TrotGait (see the file comment for meanings and ranges).
struct TrotGaitParams {
  std::string base_body;
  std::array<TrotLegConfig, 4> legs;  ///< FR, FL, RR, RL
  std::vector<TimedTrotCommand> commands;
  std::vector<Eigen::Vector2d> waypoints;  ///< world x, y (m); empty = no waypoint mode
  bool loop = true;
  double speed_m_s = 0.5;
  double max_yaw_rate_deg_s = 60;
  double tolerance_m = 0.15;
  double period_sec = 0.36;
  double duty = 0.5;
  double swing_height_m = 0.08;
  std::optional<double> body_height_m;
  std::optional<double> raibert_gain;
  std::optional<double> max_step_m;
  double max_accel_m_s2 = 1.5;
  double max_yaw_accel_rad_s2 = 3;
  double kp_xy = 25, kd_xy = 8;
  double kp_z = 400, kd_z = 40;
  double kp_tilt = 400, kd_tilt = 40;
  double kp_yaw = 150, kd_yaw = 25;
  double swing_kp = 60, swing_kd = 1.5;
  double stance_kd = 0.5;
  double friction = 0.6;
  std::vector<std::pair<std::string, double>> hold;  ///< actuator (full name) -> ctrl
  double rate_hz = 250;

  /// leg keys in the order of `legs`.
  static constexpr std::array<const char*, 4> kLegNames = {"FR", "FL", "RR", "RL"};

  /// reads the keys above from `params`; local names get `name_prefix`.
  /// @throws ConfigError for missing/unknown keys and out-of-range values.
  static TrotGaitParams Parse(ControllerParams& params, const std::string& name_prefix);
  /// @throws ConfigError (in `context`) if a value is out of range.
  void ValidateOrThrow(const ControllerContext& context) const;
};

/// the trot gait controller (see the file comment).
class TrotGait final : public Controller, public TwistTarget, public WaypointTarget {
 public:
  /// @throws ConfigError if `params` are out of range.
  TrotGait(TrotGaitParams params, ControllerContext context);

  std::string type() const override { return "trot_gait"; }
  double rate_hz() const override { return params_.rate_hz; }
  std::vector<NameRequirement> RequiredNames() const override;
  void Compute(const ControlInput& input, std::span<double> ctrl) override;
  /// forgets the start pose, references, ground plane, stance and swing state and the
  /// commands set since (twist override, SetWaypoints: the configured route restarts).
  void Reset() override;
  /// twist tracking at the last update: the slew-limited reference() minus the measured
  /// velocity of the centre of mass (heading frame: x forward, y left, m/s) and the trunk's yaw
  /// rate (rad/s): "vx_error_m_s", "vy_error_m_s", "yaw_rate_error_rad_s".
  std::vector<std::string> tracking_error_labels() const override {
    return {"vx_error_m_s", "vy_error_m_s", "yaw_rate_error_rad_s"};
  }
  void AppendTrackingError(std::vector<double>* out) const override {
    out->insert(out->end(), tracking_.begin(), tracking_.end());
  }

  /// programmatic command source (e.g. a middleware's cmd_vel): from the next update on,
  /// `command` replaces the waypoints and the scripted list until ClearTwist() (the
  /// route pauses meanwhile). call it from the thread that steps the simulation, between
  /// steps.
  void SetTwist(const TrotCommand& command) override { override_ = command; }
  /// returns to the waypoints (if configured and not finished), else the script.
  void ClearTwist() override { override_.reset(); }
  /// a legged base moves sideways.
  bool lateral() const override { return true; }
  /// replaces the waypoints (world x, y, m; at least 1) with `loop` from the next update on
  /// (waypoint mode, also for a gait configured without waypoints) and clears a SetTwist
  /// override; speed, yaw-rate limit and tolerance stay. physics thread, between steps.
  /// @throws Error for an empty list or a non-finite coordinate.
  void SetWaypoints(std::vector<Eigen::Vector2d> waypoints, bool loop) override;

  const TrotGaitParams& params() const { return params_; }
  /// the command in force at the last update (set, from the waypoints or scripted).
  const TrotCommand& command() const { return command_; }
  /// progress along the waypoints; nullptr without waypoint mode.
  const WaypointRoute* route() const { return route_ ? &*route_ : nullptr; }
  /// the slew-limited reference twist at the last update.
  const TrotCommand& reference() const { return reference_; }
  /// leg geometry read from the model (FR, FL, RR, RL); valid after Initialize.
  const std::array<LegGeometry, 4>& leg_geometry() const { return geometry_; }
  /// hip (abduction axis) positions in the base frame (m); valid after Initialize.
  const std::array<Eigen::Vector3d, 4>& hip_offsets() const { return hip_B_; }
  /// the robot's mass (kg, base body subtree); valid after Initialize.
  double mass_kg() const { return mass_; }
  /// stance flags of the last update (FR, FL, RR, RL).
  const std::array<bool, 4>& stance() const { return stance_; }
  /// desired ground reaction forces of the last update (world frame, N).
  const std::array<Eigen::Vector3d, 4>& stance_forces() const { return forces_; }
  /// target COM height above the ground plane (m); set at the first update unless given.
  double body_height_m() const { return h_ref_; }

 protected:
  void OnInitialize(const ModelInfo& model, const std::vector<int>& ids) override;

 private:
  struct Leg {
    std::array<int, 3> qpos{}, dof{}, act{};
    std::array<ActuatorInfo, 3> actuator{};  ///< hip, thigh, calf drives (actuator_drive.h)
    std::array<double, 3> q_lo{}, q_hi{};
    int calf_body = -1;
    Eigen::Vector3d foot_C = Eigen::Vector3d::Zero();    ///< foot point in the calf body frame
    Eigen::Vector3d p_lift = Eigen::Vector3d::Zero();    ///< world, at lift-off
    Eigen::Vector3d p_ground = Eigen::Vector3d::Zero();  ///< world, last stance position
    bool in_swing = false;
  };

  TrotCommand ScriptedCommand(double t) const;
  void FirstUpdate(const ControlInput& in, const Eigen::Vector3d& com,
                   const std::array<Eigen::Vector3d, 4>& feet);

  TrotGaitParams params_;
  int base_ = -1;
  std::array<Leg, 4> legs_;
  std::array<LegGeometry, 4> geometry_;
  std::array<Eigen::Vector3d, 4> hip_B_;
  std::vector<int> bodies_;  ///< base subtree with mass
  std::vector<double> body_mass_;
  std::vector<Eigen::Vector3d> body_com_B_;  ///< COM in each body's frame
  double mass_ = 0;
  Eigen::Matrix3d inertia_B_ = Eigen::Matrix3d::Identity();  ///< about the COM, base axes
  std::vector<std::pair<int, double>> hold_;                 ///< actuator index, ctrl
  StanceForceLimits limits_;
  double leg_length_ = 0.426;  ///< mean thigh + calf length (m)
  double step_limit_ = 0.17;
  std::array<double, 3> tracking_ = {NAN, NAN, NAN};  ///< see tracking_error_labels()

  std::optional<TrotCommand> override_;
  std::optional<WaypointRoute> route_;
  TrotCommand command_, reference_;
  bool started_ = false;
  double last_t_ = 0;
  double h_ref_ = 0, k_raibert_ = 0;
  double psi_ref_ = 0;
  Eigen::Vector2d p_ref_ = Eigen::Vector2d::Zero();
  Eigen::Vector3d plane_{0, 0, 0};  ///< ground z = a + b x + c y
  std::array<bool, 4> stance_{true, true, true, true};
  std::array<Eigen::Vector3d, 4> forces_;
};

}  // namespace penumbra
