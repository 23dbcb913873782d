#pragma once
// keyframe_playback: plays a timed sequence of joint configurations, from MJCF <key>s by
// name or from a CSV file of joint targets over time, interpolating linearly in between;
// the joint servo (control/joint_servo.h) tracks the result.
//
// world-file block (robot-local names get the "<robot>/" prefix):
//   controller:
//     type: keyframe_playback
//     joints: [...]              # JointServo keys (joint_servo.h): joints, actuators, output,
//     actuators: [...]           # kp, kd, gravity_compensation, max_velocity, max_effort,
//                                # limit_margin
//     frames:                    # exactly one of frames and csv
//       - {t: 0.0, key: home}    # an MJCF <key> (its qpos at the controller's joints)
//       - {t: 2.0, q: [...]}     # or joint values (rad or m, one per joint)
//       - {t: 3.0, key: rest, gripper: 0.0}   # gripper: override the key's gripper value
//     csv: motions/wave.csv      # relative to the world file's folder; see below
//     loop: false                # start over after the last frame (default false)
//     gripper_actuator: gripper  # optional: a position actuator whose ctrl follows the
//     gripper_joint: finger_joint1  # value of gripper_joint in the frames (required with it)
//     rate_hz: 0                 # control rate on sim time; 0 = every physics step
//
// CSV format: a header line `time_sec,<joint>,<joint>,...` naming every controller joint
// (robot-local names, any order; plus gripper_joint when there is a gripper), then one row
// of numbers per frame; times >= 0 and strictly increasing. blank lines and lines starting
// with '#' are skipped. errors name the CSV file and line.
//
// playback: frame times count from the first control update (normally t = 0). frame times
// must increase strictly. before the first frame the reference moves from the
// configuration at the first update (an implicit frame at time 0) when the first frame
// is later than 0. between frames i and i+1 the target is
//   q(t) = q_i + (t - t_i) / (t_{i+1} - t_i) (q_{i+1} - q_i)
// and after the last frame it holds (or, with loop, the timeline repeats with period
// t_last, and the first frame's segment then starts from the last frame). the servo
// reference follows q(t) through JointServo::StepTowards: exactly while q(t) moves within
// max_velocity and max_acceleration, otherwise (jumps, corners between segments) along a
// trapezoidal velocity profile within those limits; qd_ref = its rate of change.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "penumbra/control/controller.h"
#include "penumbra/control/controller_params.h"
#include "penumbra/control/joint_servo.h"

namespace penumbra {

/// one frame of a playback.
struct PlaybackFrame {
  double time_sec = 0;
  std::string key;                ///< full MJCF key name, or "" when q is given
  std::vector<double> q;          ///< (n) joint values when key is ""
  std::optional<double> gripper;  ///< gripper_joint value (overrides the key's)
};

/// parameters of a KeyframePlayback (see the file comment).
struct KeyframePlaybackParams {
  JointServoParams servo;
  std::vector<PlaybackFrame> frames;  ///< from `frames` or read from `csv`
  std::string csv_path;               ///< absolute path of the CSV, "" when frames were given
  bool loop = false;
  std::string gripper_actuator;  ///< full model name, "" = none
  std::string gripper_joint;     ///< full model name
  double rate_hz = 0;

  /// reads the keys above (and the CSV file); names get `name_prefix`; a relative csv
  /// path resolves against the folder of `world_file` (the context's file).
  /// @throws ConfigError for missing/unknown keys, bad values, and CSV problems (naming
  ///         the CSV file and line).
  static KeyframePlaybackParams Parse(ControllerParams& params, const std::string& name_prefix);
  /// @throws ConfigError (in `context`) for inconsistent values.
  void ValidateOrThrow(const ControllerContext& context) const;
};

/// reads a CSV of joint targets (format in the file comment). `columns` are the expected
/// joint column names (robot-local) in controller order; returns frames with q in that
/// order and, when `gripper_column` is not empty, its values as PlaybackFrame::gripper.
/// the file is read whole by core/input_file.h's ReadInputFile: a regular file only (a FIFO,
/// folder or device is refused naming what it is, without blocking), at most 256 MiB.
/// @throws ConfigError(csv_path, line, "", ...) for a missing or non-regular file, bad header
///         or rows.
std::vector<PlaybackFrame> ReadJointCsv(const std::string& csv_path,
                                        const std::vector<std::string>& columns,
                                        const std::string& gripper_column);

/// keyframe / CSV playback controller (see the file comment).
class KeyframePlayback final : public Controller {
 public:
  /// @throws ConfigError if `params` are inconsistent.
  KeyframePlayback(KeyframePlaybackParams params, ControllerContext context);

  std::string type() const override { return "keyframe_playback"; }
  double rate_hz() const override { return params_.rate_hz; }
  std::vector<NameRequirement> RequiredNames() const override;
  void Compute(const ControlInput& input, std::span<double> ctrl) override;
  /// restarts the playback: the next update takes the start pose again.
  void Reset() override;

  const KeyframePlaybackParams& params() const { return params_; }
  const JointServo& servo() const { return servo_; }
  /// (n) the interpolated target (the servo clamps it into the joint ranges) and the servo
  /// reference of the last update.
  const Eigen::VectorXd& target() const { return target_; }
  const Eigen::VectorXd& q_ref() const { return q_ref_; }
  /// true once the last frame's time has passed (never with loop).
  bool finished() const { return finished_; }

  /// the target `q` and its rate of change `qd` ((n) each) and the gripper value at
  /// playback time `t_rel` (s since the first update), for a timeline whose implicit start
  /// configuration is `q_start` / `gripper_start`; exposed for tests. valid after Initialize.
  void Evaluate(double t_rel, const Eigen::VectorXd& q_start, double gripper_start,
                Eigen::VectorXd* q, Eigen::VectorXd* qd, double* gripper) const;

 protected:
  void OnInitialize(const ModelInfo& model, const std::vector<int>& ids) override;

 private:
  KeyframePlaybackParams params_;
  JointServo servo_;
  // resolved frames: times, (n) joint values and the gripper value
  std::vector<double> times_;
  std::vector<Eigen::VectorXd> qs_;
  std::vector<double> grippers_;
  int gripper_actuator_ = -1, gripper_qpos_adr_ = -1;
  bool started_ = false, finished_ = false;
  double start_time_ = 0, last_time_ = 0, gripper_start_ = 0;
  Eigen::VectorXd q_, qd_, q_start_, target_, target_velocity_, q_ref_, qd_ref_;
};

}  // namespace penumbra
