#pragma once
// simulated time on the physics step count: the rate of a timestep and the exact time of step
// n. engine-neutral, so that everything scheduled on physics steps (physics/simulation.h,
// sensors/sensor_schedule.h) agrees on the same instants.

#include <cstdint>

namespace penumbra {

/// the physics rate 1 / timestep_sec (Hz), snapped to the nearest integer when it is within
/// 1e-9 (relative) of one: 0.002 s -> exactly 500 Hz.
double PhysicsRateHz(double timestep_sec);

/// sim time of physics step n (s): the smallest double >= n / R, R = PhysicsRateHz(timestep)
/// when that is an integer, else >= n * timestep (both exact, not summed). so for a rate r
/// dividing R, the step of frame k = n r / R has time >= k / r exactly and
/// floor(time * r) == k, and times never drift (MuJoCo's own time += timestep does, by up
/// to ~1e-11 s over a minute). n <= 0 gives 0.
double SimTimeOfStep(int64_t n, double timestep_sec);

}  // namespace penumbra
