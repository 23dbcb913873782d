#include "penumbra/sensors/sensor_schedule.h"

#include <cmath>

#include "penumbra/core/error.h"
#include "penumbra/scene/sim_time.h"

namespace penumbra {
namespace {

// sign of t f - k, exactly (one rounding of the exact value keeps its sign)
bool AtOrAfter(double t, double f, int64_t k) {
  return std::fma(t, f, -static_cast<double>(k)) >= 0;
}

}  // namespace

SensorSchedule::SensorSchedule(double timestep_sec) : timestep_sec_(timestep_sec) {
  if (!(std::isfinite(timestep_sec) && timestep_sec > 0))
    throw Error("sensor schedule: timestep " + std::to_string(timestep_sec) +
                " s is not valid; expected a finite number > 0");
  physics_rate_hz_ = PhysicsRateHz(timestep_sec);
}

int SensorSchedule::Add(const std::string& name, double rate_hz, double latency_sec) {
  if (!(std::isfinite(rate_hz) && rate_hz > 0))
    throw Error("sensor '" + name + "': rate_hz " + std::to_string(rate_hz) +
                " is not valid; expected a finite number > 0 (Hz)");
  if (!(std::isfinite(latency_sec) && latency_sec >= 0))
    throw Error("sensor '" + name + "': latency_sec " + std::to_string(latency_sec) +
                " is not valid; expected a finite number >= 0 (s)");
  Entry e;
  e.name = name;
  e.rate_hz = rate_hz;
  e.latency_sec = latency_sec;
  e.every_step = rate_hz >= physics_rate_hz_ * (1 - 1e-9);
  e.above = rate_hz > physics_rate_hz_ * (1 + 1e-9);
  entries_.push_back(e);
  return static_cast<int>(entries_.size()) - 1;
}

double SensorSchedule::effective_rate_hz(int id) const {
  const Entry& e = entries_.at(id);
  return e.every_step ? physics_rate_hz_ : e.rate_hz;
}

void SensorSchedule::StartAt(int64_t step) {
  if (step < 0) throw Error("sensor schedule: start step " + std::to_string(step) + " < 0");
  if (step == 0) return;
  // after the step before: the first k with k > t f (as Due leaves it after any firing)
  const double t = SimTimeOfStep(step - 1, timestep_sec_);
  for (Entry& e : entries_) {
    if (e.every_step) {
      e.next = step;
      continue;
    }
    int64_t k = static_cast<int64_t>(std::floor(t * e.rate_hz)) + 1;
    while (k > 0 && !AtOrAfter(t, e.rate_hz, k - 1)) --k;
    while (AtOrAfter(t, e.rate_hz, k)) ++k;
    e.next = k;
  }
}

double SensorSchedule::NominalTime(int id, int64_t k) const {
  return static_cast<double>(k) / entries_.at(id).rate_hz;
}

void SensorSchedule::Due(int64_t step, std::vector<SensorFiring>* out) {
  const double t = SimTimeOfStep(step, timestep_sec_);
  for (size_t i = 0; i < entries_.size(); ++i) {
    Entry& e = entries_[i];
    SensorFiring f;
    f.sensor = static_cast<int>(i);
    f.capture_time_sec = t;
    f.delivery_time_sec = t + e.latency_sec;
    if (e.every_step) {
      f.index = e.next++;
      f.nominal_time_sec = t;
      out->push_back(f);
      continue;
    }
    if (!AtOrAfter(t, e.rate_hz, e.next)) continue;
    f.index = e.next;
    f.nominal_time_sec = static_cast<double>(e.next) / e.rate_hz;
    out->push_back(f);
    // the next sample is the first k with k > t f; any between were due in this same step
    // (computed, not stepped through one by one)
    int64_t k = static_cast<int64_t>(std::floor(t * e.rate_hz)) + 1;
    while (k > e.next + 1 && !AtOrAfter(t, e.rate_hz, k - 1)) --k;
    while (AtOrAfter(t, e.rate_hz, k)) ++k;
    if (k <= e.next) k = e.next + 1;
    e.skipped += k - e.next - 1;
    e.next = k;
  }
}

}  // namespace penumbra
