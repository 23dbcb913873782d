#pragma once
// upper bounds of controller parameters read from a world file (the `controller:` block of a
// robot). every number a controller reads is finite and checked against one of these at parse
// time, so that absurd but finite input (a speed of 1e300 m/s, a gain of 1e300, a target at
// 1e300 m) is refused with the file, line, key path and range instead of ending in NaN physics
// or a hang. docs/robots/controller-limits.md lists them.
//
// why these values: they sit far above anything a real robot does (so no valid world is
// refused) and far below where products of them overflow or lose all precision. the position
// and time bounds are core/magnitude_limits.h's kMaxPositionM and kMaxDurationSec, the rate
// bound is 1 / kMinTimestepSec (control cannot run faster than physics).

#include <numbers>

#include "penumbra/core/magnitude_limits.h"

namespace penumbra {

/// largest |coordinate| (m) of a target, waypoint or altitude, and largest length parameter
/// (wheel radius, track width, tolerance, leash, step length, ...), as kMaxPositionM.
inline constexpr double kMaxParamPositionM = kMaxPositionM;
/// largest linear speed (m/s): speeds, speed limits and velocity commands.
inline constexpr double kMaxParamSpeedMS = 100;
/// largest angular speed, in deg/s (100 turns per second) and in rad/s.
inline constexpr double kMaxParamAngularSpeedDegS = 36000;
inline constexpr double kMaxParamAngularSpeedRadS =
    kMaxParamAngularSpeedDegS * std::numbers::pi / 180;
/// largest |angle| (deg) of a heading target (yaw_deg): 100 turns.
inline constexpr double kMaxParamAngleDeg = 36000;
/// largest linear acceleration (m/s^2; about 1000 g) and jerk (m/s^3).
inline constexpr double kMaxParamAccelerationMS2 = 1e4;
inline constexpr double kMaxParamJerkMS3 = 1e6;
/// largest angular acceleration (rad/s^2).
inline constexpr double kMaxParamAngularAccelerationRadS2 = 1e6;
/// largest controller gain, damping or threshold (any unit: P, I and D gains, kp and kd of a
/// servo, IK damping).
inline constexpr double kMaxParamGain = 1e6;
/// largest rate (Hz) of a controller or filter: 1 / kMinTimestepSec.
inline constexpr double kMaxParamRateHz = 1 / kMinTimestepSec;
/// largest time (s) of a scripted command or keyframe, as kMaxDurationSec.
inline constexpr double kMaxParamTimeSec = kMaxDurationSec;
/// largest |joint value| (rad or m): joint targets, postures, keyframes, gripper values,
/// joint-space margins and zones.
inline constexpr double kMaxParamJointValue = 1e5;
/// largest joint velocity (rad/s or m/s) and joint acceleration (rad/s^2 or m/s^2).
inline constexpr double kMaxParamJointVelocity = 1e4;
inline constexpr double kMaxParamJointAcceleration = 1e6;
/// largest |effort| (N or N m) and |actuator ctrl value| a controller may command or hold.
inline constexpr double kMaxParamEffort = 1e9;

}  // namespace penumbra
