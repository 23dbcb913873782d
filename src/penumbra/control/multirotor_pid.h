#pragma once
// cascaded PID flight controller for multirotors (any rotor layout the model describes,
// see control/multirotor_model.h), with takeoff, hover, waypoint and velocity modes.
//
// world-file block (robot-local names get the "<robot>/" prefix):
//   controller:
//     type: multirotor_pid
//     base_body: base                 # the airframe's free body
//     rotor_actuators: [thrust_fr, thrust_rl, thrust_fl, thrust_rr]   # >= 4, site transmission
//     rate_hz: 500                    # > 0, control rate on sim time (default 500)
//     commands:                       # scripted, on sim time (default: none = idle)
//       - {t: 0, mode: takeoff, altitude_m: 1.5}
//       - {t: 6, mode: waypoints, waypoints: [[4, 0, 1.5], [4, 4, 1.5]], speed_m_s: 1.0}
//     # optional limits and gains, defaults below (see docs/robots/quadrotor.md)
//
// commands (`t`: sim time in s >= 0, non-decreasing; `mode` picks the rest):
//   idle       rotors at their minimum thrust (motors off); the controller's state resets.
//   takeoff    altitude_m (required, world z of the base origin), speed_m_s (climb, default
//              1.0), yaw_deg: climb vertically from where the reference is (the vehicle's
//              position when idle) to the altitude, then hold there.
//   hover      position [x, y, z] (default: the current reference, i.e. stop and hold),
//              speed_m_s (default 1.0, to fly to position), yaw_deg.
//   waypoints  waypoints [[x, y, z], ...] (>= 1, world m), speed_m_s (default 1.0),
//              yaw_deg, face_path (default false: nose along each segment): fly the straight
//              lines from the current reference through the points, stopping at each corner
//              (MultirotorPath), then hold the last point.
//   velocity   velocity_m_s [vx, vy, vz] (default 0), yaw_rate_deg_s (default 0), frame
//              (world | heading; heading = level frame turned by the reference yaw, x
//              forward, as ROS cmd_vel for a multirotor): the reference velocity approaches
//              the command with a 0.25 s time constant, limited to max_accel_m_s2 and
//              max_jerk_m_s3; the position reference integrates it (so it holds position once
//              the velocity is zero) and is kept within leash_m of the vehicle.
//   land       descend vertically at land_speed_m_s (as a velocity command); touchdown is
//              when the vehicle stays more than 0.3 m above its sinking reference with
//              |v_z| < 0.1 m/s for 0.3 s: then the rotors stop (mode idle).
//   yaw_deg, when given, turns the reference heading at yaw_speed_deg_s; otherwise the
//   heading holds. a command applies at the first control update at or after its t.
//   SetCommand() (programmatic) replaces the current command at the next update; the next
//   scripted command still applies at its time.
//
// control law, every update, with state p, v (world, base origin), R = R_WB, w (body rates),
// airframe mass m and inertia J about the COM (MultirotorModel), gravity g e_z:
//   reference   p_r, v_ff, a_ff from the mode (MultirotorPath for takeoff, hover and
//               waypoints; its clock slows linearly from 1 to 0 as |p_r - p| goes from
//               leash_m / 2 to leash_m, so the reference waits for a lagging vehicle).
//   position P  v_sp = v_ff + Kp_pos (p_r - p), |v_sp,xy| <= max_speed_xy_m_s,
//               -max_descent_m_s <= v_sp,z <= max_climb_m_s.
//   velocity    a_sp = a_ff + Kp_vel e_v + I_vel - Kd_vel dv/dt,  e_v = v_sp - v,
//   PID         I_vel += Ki_vel clip(e_v, +-0.5 m/s) dt, |I| <= velocity_i_limit_m_s2; frozen
//               on an axis while the output on it saturates (tilt limit, mixer) and while the
//               thrust axis is > 20 deg from its setpoint (anti-windup: upsets and large
//               steps leave it alone); dv/dt low-passed at derivative_cutoff_hz.
//   thrust      F = m (a_sp + g e_z), F_z >= 0.1 m g, |F_xy| <= F_z tan(max_tilt_deg);
//   vector      collective T = F . R e_z (thrust along the current body z; T. Lee, M. Leok,
//               N. H. McClamroch, "Geometric tracking control of a quadrotor UAV on SE(3)",
//               CDC 2010; D. Mellinger and V. Kumar, "Minimum snap trajectory generation and
//               control for quadrotors", ICRA 2011).
//   attitude    b3 = F / |F|, b2 = b3 x (cos psi_r, sin psi_r, 0) / |.|, b1 = b2 x b3,
//   setpoint    R_d = [b1 b2 b3] (yaw decoupled from the thrust direction).
//   attitude P  reduced attitude first: q_red = the shortest rotation taking R e_z to b3,
//               applied to q; the remaining rotation to q_d is about b3 and is scaled by
//               Kp_yaw / Kp_roll_pitch; w_sp = 2 Kp_roll_pitch sign(q_e.w) vec(q_e),
//               q_e = q^-1 q_d' (D. Brescianini, M. Hehn, R. D'Andrea, "Nonlinear quadrocopter
//               attitude control", ETH Zurich tech. report, 2013; the PX4 multicopter
//               attitude controller), plus the yaw-rate feed-forward; each axis limited to
//               max_roll_pitch_rate_deg_s / max_yaw_rate_deg_s. the rate feed-forward
//               turns the thrust direction as the reference's jerk j_ff demands
//               (differential flatness, Mellinger and Kumar 2011, eq. 7-8):
//               w_ff = R^T (b3 x (m / |F|) (j_ff - (j_ff . b3) b3)).
//   rate PID    alpha = Kp_rate e_w + I_rate - Kd_rate dw/dt, e_w = w_sp - w, I frozen on
//               axes whose torque the mixer had to cut; torque tau = J alpha + w x J w.
//   mixer       per-rotor thrusts from (T, tau) with roll/pitch > collective > yaw priority
//               (MultirotorMixer), written to the rotors' ctrl.
// cascade structure and default gains follow the PX4 multicopter controllers (PX4 user
// guide, "Controller Diagrams", multicopter position and attitude control); the controller
// uses the simulator's true state (no estimator).
//
// thread safety: Compute runs on the physics thread; SetCommand may be called from any
// thread (the command is handed over under a mutex). accessors are for the physics thread.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <atomic>
#include <limits>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "penumbra/control/controller.h"
#include "penumbra/control/controller_params.h"
#include "penumbra/control/multirotor_mixer.h"
#include "penumbra/control/multirotor_model.h"
#include "penumbra/control/multirotor_path.h"

namespace penumbra {

/// what the multirotor should do (see the file comment for each mode's meaning).
struct MultirotorCommand {
  enum class Mode { kIdle, kTakeoff, kHover, kWaypoints, kVelocity, kLand };
  enum class Frame { kWorld, kHeading };

  Mode mode = Mode::kHover;
  double altitude_m = 1.5;                  ///< takeoff: target world z of the base origin (m)
  std::optional<Eigen::Vector3d> position;  ///< hover: where to hold (world, m)
  std::vector<Eigen::Vector3d> waypoints;   ///< waypoints: world points (m), at least 1
  double speed_m_s = 1.0;         ///< takeoff climb, hover transfer, waypoint cruise (> 0)
  std::optional<double> yaw_deg;  ///< takeoff/hover/waypoints: heading to turn to (deg)
  bool face_path = false;         ///< waypoints: point the nose along each segment
  Eigen::Vector3d velocity_m_s = Eigen::Vector3d::Zero();  ///< velocity: (vx, vy, vz)
  double yaw_rate_deg_s = 0;    ///< velocity: yaw rate (deg/s, + = counter-clockwise)
  Frame frame = Frame::kWorld;  ///< velocity: axes of velocity_m_s

  /// mode name as written in world files ("idle", "takeoff", ...).
  static const char* ModeName(Mode mode);
  /// @throws ConfigError(context, `key`...) for non-finite values, speed <= 0, or waypoints
  ///         mode without waypoints.
  void ValidateOrThrow(const ControllerContext& context, const std::string& key) const;
};

/// a scripted command and the sim time it starts at.
struct TimedMultirotorCommand {
  double t_sec = 0;
  MultirotorCommand command;
};

/// parameters of a MultirotorPid (see the file comment and docs/robots/quadrotor.md).
struct MultirotorPidParams {
  std::string base_body;                     ///< full model name, e.g. "drone/base"
  std::vector<std::string> rotor_actuators;  ///< full model names, >= 4
  double rate_hz = 500;
  double gravity_m_s2 = 9.81;  ///< |g| of the world (MuJoCo's default 9.81)

  // limits
  double max_speed_xy_m_s = 5;
  double max_climb_m_s = 2;
  double max_descent_m_s = 1.5;
  double max_accel_m_s2 = 2;  ///< path and velocity-command acceleration
  double max_jerk_m_s3 = 10;  ///< velocity-command (and land) jerk
  double max_tilt_deg = 35;
  double max_roll_pitch_rate_deg_s = 220;
  double max_yaw_rate_deg_s = 150;
  double yaw_speed_deg_s = 60;  ///< heading slew for yaw_deg / face_path
  double leash_m = 1.0;         ///< farthest the reference may run ahead of the vehicle
  double land_speed_m_s = 0.5;  ///< descent speed of the land mode

  // gains (position: 1/s; velocity P: 1/s, I: 1/s^2, D: -; attitude: 1/s;
  // rate P: 1/s, I: 1/s^2, D: -)
  double position_p_xy = 1.5, position_p_z = 1.5;
  double velocity_p_xy = 3.5, velocity_i_xy = 2.0, velocity_d_xy = 0.0;
  double velocity_p_z = 5.0, velocity_i_z = 3.0, velocity_d_z = 0.0;
  double velocity_i_limit_m_s2 = 3.0;
  double attitude_p_roll_pitch = 8.0, attitude_p_yaw = 3.0;
  double rate_p_roll_pitch = 25.0, rate_i_roll_pitch = 10.0, rate_d_roll_pitch = 0.0;
  double rate_p_yaw = 12.0, rate_i_yaw = 3.0, rate_d_yaw = 0.0;
  double rate_i_limit_rad_s2 = 30.0;
  double derivative_cutoff_hz = 20.0;

  std::vector<TimedMultirotorCommand> commands;  ///< sorted by t_sec (non-decreasing)

  /// reads the keys from `params`; local names get `name_prefix` ("drone/" or "").
  /// @throws ConfigError for missing/unknown keys and out-of-range values, naming the key
  ///         path, e.g. "robots[drone].controller.commands[1].altitude_m".
  static MultirotorPidParams Parse(ControllerParams& params, const std::string& name_prefix);
  /// @throws ConfigError (in `context`) if a value is out of range.
  void ValidateOrThrow(const ControllerContext& context) const;
};

/// the cascaded multirotor controller (see the file comment).
class MultirotorPid final : public Controller {
 public:
  /// @throws ConfigError if `params` are out of range.
  MultirotorPid(MultirotorPidParams params, ControllerContext context);

  std::string type() const override { return "multirotor_pid"; }
  double rate_hz() const override { return params_.rate_hz; }
  std::vector<NameRequirement> RequiredNames() const override;
  void Compute(const ControlInput& input, std::span<double> ctrl) override;
  /// forgets the command being flown, a pending SetCommand, the script position, the
  /// references, integrators and derivative filters: idle until the script or a command
  /// says otherwise.
  void Reset() override;

  /// replaces the current command at the next control update (programmatic command source,
  /// e.g. middleware). thread-safe.
  /// @throws ConfigError (key "command") if the command is invalid.
  void SetCommand(const MultirotorCommand& command);

  const MultirotorPidParams& params() const { return params_; }
  /// airframe mass properties and rotor allocation read from the model (after Initialize).
  const MultirotorModel& airframe() const { return airframe_; }
  /// mode of the command being flown.
  MultirotorCommand::Mode mode() const { return mode_; }
  /// reference position (world, m), velocity feed-forward (m/s) and yaw (rad) of the last update.
  const Eigen::Vector3d& reference_position() const { return p_ref_; }
  const Eigen::Vector3d& reference_velocity() const { return v_ff_; }
  double reference_yaw() const { return yaw_ref_; }
  /// the path of the current takeoff / hover / waypoints command.
  const MultirotorPath& path() const { return path_; }
  /// true once the path's reference has come to rest at its last point.
  bool path_finished() const { return path_time_ >= path_.duration_sec(); }
  /// what the mixer gave up at the last update, and the rotor thrusts it wrote (N).
  const MixResult& last_mix() const { return mix_; }
  const std::vector<double>& rotor_thrust_n() const { return thrust_; }

 protected:
  void OnInitialize(const ModelInfo& model, const std::vector<int>& ids) override;

 private:
  void ApplyCommand(const MultirotorCommand& cmd, const Eigen::Vector3d& p, double yaw);
  void UpdateReference(double dt, const Eigen::Vector3d& p);
  void ResetState();

  MultirotorPidParams params_;
  int base_ = -1;
  std::vector<int> rotors_;
  MultirotorModel airframe_;
  MultirotorMixer mixer_;

  // command hand-over from SetCommand
  std::mutex pending_mutex_;
  std::atomic<bool> has_pending_{false};
  MultirotorCommand pending_;
  size_t next_scripted_ = 0;

  // command being flown
  MultirotorCommand::Mode mode_ = MultirotorCommand::Mode::kIdle;
  MultirotorPath path_;
  double path_time_ = 0;
  bool face_path_ = false;
  Eigen::Vector3d v_cmd_ = Eigen::Vector3d::Zero();
  double yaw_rate_cmd_ = 0;
  double touchdown_sec_ = 0;  ///< how long the land mode has seen the vehicle resting
  MultirotorCommand::Frame frame_ = MultirotorCommand::Frame::kWorld;

  // reference
  Eigen::Vector3d p_ref_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_ff_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d a_ff_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d j_ff_ = Eigen::Vector3d::Zero();
  double yaw_ref_ = 0, yaw_target_ = 0, yaw_rate_ff_ = 0;

  // loop state
  bool started_ = false;
  double t_prev_ = 0;
  Eigen::Vector3d vel_int_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d rate_int_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_prev_ = Eigen::Vector3d::Zero(), acc_filt_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d w_prev_ = Eigen::Vector3d::Zero(), wdot_filt_ = Eigen::Vector3d::Zero();
  bool have_prev_ = false;
  bool xy_limited_ = false;
  bool tilt_error_large_ = false;  ///< thrust axis > 20 deg from its setpoint
  // cached per-update constants
  double tan_max_tilt_ = 0;
  double alpha_dt_ = -1, alpha_ = 0;
  double heading_yaw_ = std::numeric_limits<double>::quiet_NaN();
  Eigen::Vector3d heading_ = Eigen::Vector3d::UnitX();
  double last_collective_request_ = 0;
  MixResult mix_;
  std::vector<double> thrust_;
};

}  // namespace penumbra
