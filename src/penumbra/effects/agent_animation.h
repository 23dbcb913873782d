#pragma once
// the moving parts of an NPC agent over sim time: a person's limbs (effects/walker_gait.h) and
// a vehicle's wheels. every agent is a set of mocap bodies (compose/agent_bodies.h): its root
// "agents/<name>", posed from the agent's path, and one body per part "agents/<name>/<part>",
// posed from the root and the part's joint angles, so the limbs and wheels are real geoms
// that collide, render and are seen by every ray query.
//
// the joint angles come from what the agent's root pose did up to time t, integrated on a
// fixed grid of kAnimationGridSec from t = 0 (AgentMotionClock): the odometer (distance along
// the heading), the speed and the yaw rate (both low-passed with time constant
// kAnimationSmoothingSec, so a stop or a turn on the spot does not snap the limbs), and the
// gait phase, the integral of the stride frequency at the smoothed speed. every value is a
// pure function of (root pose function, t), whatever times it is asked for and in which order:
// the mocap drivers (physics Simulation::AddMocapDriver) stay pure functions of sim time, so a
// run, a resimulation from a saved state and a replay give bit-identical part poses (a replay
// also restores them from the log, which records every mocap body).
//
// vehicles: each wheel spins by distance / radius about its axle (the odometer, signed:
// reversing spins it backwards); steered wheels turn by the kinematic bicycle model's angle
// delta = atan(L omega / v) for wheelbase L, yaw rate omega and speed v (Rajamani, "Vehicle
// Dynamics and Control", 2nd ed. 2012, sec. 2.2), clamped to +-kMaxSteerRad; a forklift steers
// with its rear wheels (the angle negated), a cart with its front castors.

#include <functional>
#include <string>
#include <vector>

#include "penumbra/core/pose.h"
#include "penumbra/effects/agent_path.h"
#include "penumbra/effects/walker_gait.h"

namespace penumbra {

inline constexpr double kAnimationGridSec = 0.01;       ///< integration grid, s
inline constexpr double kAnimationSmoothingSec = 0.15;  ///< low-pass time constant, s
inline constexpr double kMaxSteerRad = 1.2;             ///< steering limit, rad (69 deg)

/// one wheel of a vehicle agent, in the agent frame A (effects/agent_path.h).
struct AgentWheel {
  std::string name;        ///< part name: "wheel_fl", "wheel_fr", "wheel_rl", "wheel_rr"
  Eigen::Vector3d centre;  ///< axle centre in A, m (z = radius: it stands on the floor)
  double radius_m = 0;
  double width_m = 0;
  int steer = 0;  ///< +1 steered as the bicycle model's front wheel, -1 as its rear, 0 fixed
};

/// the wheels of a vehicle kind (none for a person): forklift r 0.25 m, wheelbase 1.1 m, rear
/// steering; cart r 0.1 m, wheelbase 0.8 m, front castors.
std::vector<AgentWheel> AgentWheels(AgentKind kind);
/// distance between the front and rear axles of AgentWheels(kind), m (0 for a person):
/// forklift 1.1 m, cart 0.8 m. the crowd's bicycle model uses it too (KindModel).
double AgentWheelbase(AgentKind kind);

/// the part names of an agent of `kind` after its root, in body order: the walker segments
/// (WalkerSegmentName) for a person, the wheels' names for a vehicle.
std::vector<std::string> AgentPartNames(AgentKind kind);

/// what the root pose did up to a time (see the file header).
struct AgentMotionState {
  double time_sec = 0;
  double distance_m = 0;     ///< odometer: path length along the heading (signed), m
  double speed_m_s = 0;      ///< smoothed horizontal speed, m/s (>= 0)
  double yaw_rate = 0;       ///< smoothed yaw rate, rad/s
  double gait_cycles = 0;    ///< integral of the stride frequency, cycles (persons)
  double raw_speed_m_s = 0;  ///< unsmoothed speed over the grid step containing t
};

/// integrates AgentMotionState on the grid for a root pose function (pure in t). caches the
/// last grid point, so increasing times cost O(1) each; an earlier time restarts from 0.
/// not thread-safe (one agent's drivers run on the loop thread).
class AgentMotionClock {
 public:
  /// @param X_WA the root's pose over sim time, a pure function of t
  /// @param hip_height_m > 0 for a person (the stride frequency's hip height), else 0
  AgentMotionClock(std::function<Pose(double)> X_WA, double hip_height_m);
  /// the state at sim time t (t < 0 counts as 0).
  AgentMotionState At(double time_sec);
  /// the root pose function.
  Pose X_WA(double time_sec) const { return X_WA_(time_sec); }

 private:
  void Advance();  // one grid step
  std::function<Pose(double)> X_WA_;
  double hip_height_m_;
  int64_t k_ = 0;  // grid index of the cached state
  AgentMotionState s_;
  Pose X_k_;  // root pose at grid point k_
};

/// the world poses of an agent's bodies (root, then AgentPartNames) over sim time.
class AgentAnimator {
 public:
  /// @param kind       person, forklift or cart
  /// @param height_m   a person's height (its skeleton; WalkerSkeleton::FromHeight), else ignored
  /// @param X_WA       the root's pose over sim time (the agent's path), a pure function of t
  /// @throws Error for a person height outside (0, 3] m.
  AgentAnimator(AgentKind kind, double height_m, std::function<Pose(double)> X_WA);

  /// X_W of the root and of every part at sim time t (root first; see AgentPartNames). the
  /// same t twice returns the cached poses.
  const std::vector<Pose>& Poses(double time_sec);
  /// the motion state at t (see AgentMotionClock).
  AgentMotionState Motion(double time_sec) { return clock_.At(time_sec); }
  /// a person's joint angles at t (all 0 for a vehicle).
  WalkerJointAngles Angles(double time_sec);
  /// a vehicle's wheel spin (rad, about the axle, positive rolling forward) and steering angle
  /// (rad, about +z of A) at t.
  double WheelSpin(double time_sec, const AgentWheel& wheel);
  double SteerAngle(double time_sec, const AgentWheel& wheel);

  AgentKind kind() const { return kind_; }
  const WalkerSkeleton& skeleton() const { return skeleton_; }

 private:
  AgentKind kind_;
  WalkerSkeleton skeleton_;
  std::vector<AgentWheel> wheels_;
  AgentMotionClock clock_;
  double cached_t_ = -1;
  std::vector<Pose> poses_;
};

/// a wheel's body frame in A at spin `spin` and steering `steer` (rad): at its centre, the
/// axle along y, rotated by steer about z, then spun about the axle.
Pose AgentWheelPose(const AgentWheel& wheel, double spin, double steer);

}  // namespace penumbra
