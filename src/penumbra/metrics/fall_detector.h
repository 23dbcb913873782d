#pragma once
// fall detection of a run's floating-base robots (docs/metrics.md "Falls"), for run.json's
// "falls" object and a warning line:
//
//   a robot has fallen when its base body is tilted more than FallRule::tilt_threshold_deg
//   (60 deg) from upright for at least FallRule::min_duration_sec (0.5 s) of simulated time.
//
// tilt = the angle between the base body's z axis and the world's z axis (up), from the
// orientation of its free joint (qpos; MuJoCo's free joint is on a child of the world body, so
// its quaternion is the body's orientation in the world frame). upright is the base frame's z
// up, the convention of every bundled robot and of MJCF robots in general (REP-103). the tilt
// is robot-independent, where a base-height rule needs each robot's standing height and the
// terrain under it (a quadruped that lies down or climbs a ramp changes height without
// falling); 60 deg is far above a trotting quadruped's tilt (measured max 3.4 deg in the
// default world, 10.6 deg on worlds/quadruped.yaml's 10 deg ramp) and well short of a robot on
// its side (90) or back (180); 0.5 s skips a brief tilt that the robot recovers from (a
// stumble, a quadrotor's bank).
//
// the fall time is the simulated time at which the tilt first exceeded the threshold in the
// first episode that lasted min_duration_sec. the detector reads simulated time and the state
// only (deterministic); it runs on a replay's recorded states the same way.

#include <Eigen/Geometry>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "penumbra/pipeline/sink.h"
#include "penumbra/world/world_config.h"

namespace penumbra {

class Simulation;

/// when a tilt counts as a fall (see the file comment).
struct FallRule {
  double tilt_threshold_deg = 60.0;  ///< (0, 180)
  double min_duration_sec = 0.5;     ///< >= 0, simulated seconds
};

/// the fall verdict of one robot.
struct RobotFall {
  std::string robot;  ///< the world file's robot name
  std::string body;   ///< its base body (the body of its free joint), e.g. "quadruped/trunk"
  bool fell = false;
  /// start of the first tilt episode that lasted min_duration_sec, s; NaN when it did not fall
  double fall_time_sec = std::numeric_limits<double>::quiet_NaN();
  double max_tilt_deg = 0;       ///< largest tilt seen, deg in [0, 180]
  double max_tilt_time_sec = 0;  ///< when it was first seen, s
};

/// the tilt from upright of a body with orientation q_WB (unit or not; MuJoCo's w, x, y, z
/// order in qpos): the angle between its z axis and the world z, deg in [0, 180].
double BaseTiltDeg(const Eigen::Quaterniond& q_WB);

/// applies FallRule to one robot's tilt samples in time order. not thread-safe.
class FallDetector {
 public:
  FallDetector(std::string robot, std::string body, FallRule rule = {});

  /// the tilt at simulated time `time_sec` (non-decreasing). returns true once: at the
  /// sample that completes the first fall.
  bool Update(double time_sec, double tilt_deg);

  const RobotFall& result() const { return result_; }
  const FallRule& rule() const { return rule_; }

 private:
  RobotFall result_;
  FallRule rule_;
  double above_since_ = std::numeric_limits<double>::quiet_NaN();  // NaN: not above now
};

/// what counts as stumbling from the initial pose: within the first `window_sec` of the run
/// the base drops more than `drop_m` below its starting height or tilts more than
/// `tilt_change_deg` away from its starting tilt. a robot standing on its controller or resting
/// on its contacts moves less (the bundled robots: a trot's tilt stays under 3.4 deg, a
/// settled start drops less than 1 cm); a model whose reference pose qpos0 is not a standing
/// one (Menagerie's ANYmal C: straight legs in the air, no actuator holding them) collapses.
struct StartRule {
  double window_sec = 1.0;        ///< > 0, simulated seconds from the first state seen
  double drop_m = 0.1;            ///< > 0, m (upward motion, e.g. a take-off, never counts)
  double tilt_change_deg = 15.0;  ///< (0, 180)
};

/// watches one robot's base over StartRule::window_sec from its first sample. not thread-safe.
class StartCheck {
 public:
  explicit StartCheck(StartRule rule = {}) : rule_(rule) {}

  /// the base's tilt (deg) and height (world z, m) at simulated time `time_sec`
  /// (non-decreasing). returns true once: at the first sample past the window when the base
  /// stumbled within it.
  bool Update(double time_sec, double tilt_deg, double base_z_m);

  double max_drop_m() const { return max_drop_m_; }                ///< within the window, m
  double max_tilt_change_deg() const { return max_tilt_change_; }  ///< within the window
  bool stumbled() const { return stumbled_; }  ///< decided once the window has passed
  const StartRule& rule() const { return rule_; }

 private:
  StartRule rule_;
  bool started_ = false, done_ = false, stumbled_ = false;
  double t0_ = 0, tilt0_ = 0, z0_ = 0, max_drop_m_ = 0, max_tilt_change_ = 0;
};

/// a robot to watch: its name, base body and the qpos index of its free joint's quaternion.
struct FallTarget {
  std::string robot;
  std::string body;
  int quat_adr = 0;  ///< qpos index of w (x, y, z follow); its position is the 3 before
  /// the world file names an initial_keyframe for the robot (the stumble warning then does not
  /// suggest one)
  bool has_initial_keyframe = false;
};

/// the robots of `world` with a free joint (the first free joint whose body's name starts
/// with "<robot>/"), in file order.
std::vector<FallTarget> FallTargets(const WorldConfig& world, const Simulation& sim);

/// watches the fall targets at every physics step (kState snapshots) and warns through
/// spdlog once per robot when it falls: "robot 'NAME' fell at T s: its base BODY tilted
/// more than 60 deg from upright for 0.5 s (max tilt X deg so far)", and once when it
/// stumbles from its initial pose (StartRule): "robot 'NAME' stumbled from its initial pose
/// in its first 1 s: its base BODY dropped D m and tilted T deg ...", with a hint to start it
/// from a standing keyframe.
class FallSink : public Sink {
 public:
  explicit FallSink(std::vector<FallTarget> targets, FallRule rule = {});

  void OnStart(const LoopStart& start) override {}
  /// kState at every step.
  SnapshotContent Wants(int64_t step, double time_sec) override;
  /// updates every robot's detector from the snapshot's qpos.
  void OnSnapshot(const std::shared_ptr<const WorldSnapshot>& snapshot) override;
  void OnFinish(const LoopFinish& finish) override {}

  /// the verdicts, in target order.
  std::vector<RobotFall> Results() const;

  /// run.json's "falls" object as JSON text: {"rule": "...", "tilt_threshold_deg",
  /// "min_duration_sec", "robots": {NAME: {"base_body", "fell", "fall_time_sec" (null when
  /// it did not fall), "max_tilt_deg", "max_tilt_time_sec", "start_drop_m",
  /// "start_tilt_change_deg", "stumbled_at_start"}}} (the start figures: StartRule's window).
  std::string SummaryJson() const;

 private:
  std::vector<FallTarget> targets_;
  std::vector<FallDetector> detectors_;
  std::vector<StartCheck> starts_;
  FallRule rule_;
};

/// the FallSink of `world` for a loaded simulation, or nullptr when no robot has a free joint.
std::unique_ptr<FallSink> MakeFallSink(const WorldConfig& world, const Simulation& sim);

}  // namespace penumbra
