#pragma once
// when sensors fire, on simulation time. used by the run's sensor stage and usable for
// cameras: sample k of a sensor with rate f is captured at the first physics step whose
// time is >= k / f (never drifts, whatever the ratio of rate and timestep). a sensor faster
// than the physics rate fires at most once per step: the samples that fall inside one step
// are skipped (counted in skipped()). all sensors due at the same step see the same snapshot.
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
  double nominal_time_sec = 0;   ///< k / rate_hz
  double capture_time_sec = 0;   ///< sim time of the step it fires at (>= nominal)
  double delivery_time_sec = 0;  ///< capture_time_sec + latency_sec
};

/// fixed-rate schedules of many sensors on sim time.
class SensorSchedule {
 public:
  /// adds a sensor; returns its id (0, 1, ... in order).
  /// @throws Error if rate_hz is not finite and > 0 or latency_sec is not finite and >= 0.
  int Add(const std::string& name, double rate_hz, double latency_sec = 0.0);

  /// appends to `out` every sensor due at the physics step with time `time_sec` (in id
  /// order) and advances their next sample. call once per step with increasing times.
  void Due(double time_sec, std::vector<SensorFiring>* out);

  /// sim time of sample k of sensor `id` (k / rate_hz).
  double NominalTime(int id, int64_t k) const;

  int size() const { return static_cast<int>(entries_.size()); }
  const std::string& name(int id) const { return entries_.at(id).name; }
  double rate_hz(int id) const { return entries_.at(id).rate_hz; }
  double latency_sec(int id) const { return entries_.at(id).latency_sec; }
  /// samples skipped because the rate exceeds the physics rate.
  int64_t skipped(int id) const { return entries_.at(id).skipped; }

  /// tolerance on "time >= k / rate" (absolute, s): absorbs the rounding of MuJoCo's
  /// accumulated time (time += timestep).
  static constexpr double kToleranceSec = 1e-9;

 private:
  struct Entry {
    std::string name;
    double rate_hz = 0;
    double latency_sec = 0;
    int64_t next = 0;
    int64_t skipped = 0;
  };
  std::vector<Entry> entries_;
};

}  // namespace penumbra
