#pragma once
// when sensors (and cameras) fire, on the physics step count. sample k of a sensor with
// rate f is captured at the first physics step n whose time t_n = SimTimeOfStep(n, timestep)
// (scene/sim_time.h) is >= k / f, compared exactly (t_n f >= k): no tolerance and no
// drift, whatever the ratio of rate and timestep. when f divides the physics rate the step's
// time is >= k / f and floor(t_n f) == k for every sample.
//
// a rate at or above the physics rate fires once per physics step (index = step since the
// first Due, no gaps): exceeds_physics_rate() says whether it was above, so that callers can
// warn. below it, a sample never shares a step with the next, so none is skipped; skips are
// still computed arithmetically (never one loop turn per skipped sample).
//
// stamps: capture stamp = the sim time of that step (not k / f); delivery stamp = capture
// stamp + latency_sec (the time a consumer would receive it).

#include <cstdint>
#include <string>
#include <vector>

namespace penumbra {

/// one sample that is due now.
struct SensorFiring {
  int sensor = -1;               ///< id returned by SensorSchedule::Add
  int64_t index = 0;             ///< sample index k (0, 1, ...; skipped samples leave gaps)
  double nominal_time_sec = 0;   ///< k / rate_hz (the capture time at or above the physics rate)
  double capture_time_sec = 0;   ///< sim time of the step it fires at (>= nominal)
  double delivery_time_sec = 0;  ///< capture_time_sec + latency_sec
};

/// fixed-rate schedules of many sensors on the physics step count.
class SensorSchedule {
 public:
  /// a schedule for physics steps of `timestep_sec`.
  /// @throws Error if timestep_sec is not finite and > 0.
  explicit SensorSchedule(double timestep_sec);

  /// adds a sensor; returns its id (0, 1, ... in order).
  /// @throws Error if rate_hz is not finite and > 0 or latency_sec is not finite and >= 0.
  int Add(const std::string& name, double rate_hz, double latency_sec = 0.0);

  /// appends to `out` every sensor due at physics step `step` (time SimTimeOfStep(step)),
  /// in id order, and advances their next sample. call once per step with increasing steps
  /// (steps without a call count as passed).
  void Due(int64_t step, std::vector<SensorFiring>* out);

  /// positions every schedule added so far as if Due had been called for the steps 0 .. step - 1:
  /// the next sample of each sensor is the first one due at or after `step` (its index as in a
  /// run from step 0), and a sensor at or above the physics rate continues with index `step`.
  /// for a run that starts at a later step (a replay from --from); StartAt(0) changes nothing
  /// of a fresh schedule. call before the first Due.
  /// @throws Error if step < 0.
  void StartAt(int64_t step);

  /// sim time of sample k of sensor `id` (k / rate_hz).
  double NominalTime(int id, int64_t k) const;

  int size() const { return static_cast<int>(entries_.size()); }
  const std::string& name(int id) const { return entries_.at(id).name; }
  /// the rate given to Add.
  double rate_hz(int id) const { return entries_.at(id).rate_hz; }
  /// the rate it fires at: min(rate_hz, physics rate).
  double effective_rate_hz(int id) const;
  /// true if rate_hz is above the physics rate (it fires every step instead).
  bool exceeds_physics_rate(int id) const {
    return entries_.at(id).every_step && entries_.at(id).above;
  }
  double latency_sec(int id) const { return entries_.at(id).latency_sec; }
  /// samples skipped (several falling inside one step; only possible through rounding).
  int64_t skipped(int id) const { return entries_.at(id).skipped; }
  /// the physics rate (Hz, PhysicsRateHz of the timestep).
  double physics_rate_hz() const { return physics_rate_hz_; }

 private:
  struct Entry {
    std::string name;
    double rate_hz = 0;
    double latency_sec = 0;
    bool every_step = false;  ///< rate at or above the physics rate
    bool above = false;       ///< strictly above it
    int64_t next = 0;
    int64_t skipped = 0;
  };
  double timestep_sec_ = 0;
  double physics_rate_hz_ = 0;
  std::vector<Entry> entries_;
};

}  // namespace penumbra
