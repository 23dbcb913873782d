#pragma once
// the magnitude and time limits that several modules check input against: scene/scene_limits.h
// (world files, compiled models), control/param_limits.h (controller parameters) and command/
// (live commands) take them from here, so each value exists once. docs/world-file.md ("Input
// limits") gives the reasons.

namespace penumbra {

/// largest |coordinate| (m) of a position given at load or by a client: world-file poses and
/// light positions, sensor mounts, the centres of MJCF geoms, cameras and lights at qpos0,
/// controller targets and live waypoints. Embree traces in 32-bit floats, whose spacing is
/// 7.8 mm at 1e5 m.
inline constexpr double kMaxPositionM = 1e5;
/// physics timestep range (s), for physics.timestep_sec and the MJCF <option timestep>.
/// the lower end keeps 1 s of simulated time at <= 1e6 steps.
inline constexpr double kMinTimestepSec = 1e-6;
inline constexpr double kMaxTimestepSec = 0.1;
/// largest run duration (s of simulated time): duration_sec and --duration (11.6 days).
inline constexpr double kMaxDurationSec = 1e6;

}  // namespace penumbra
