#include "penumbra/sensors/sensor_schedule.h"

#include <cmath>

#include "penumbra/core/error.h"

namespace penumbra {

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
  entries_.push_back(e);
  return static_cast<int>(entries_.size()) - 1;
}

double SensorSchedule::NominalTime(int id, int64_t k) const {
  return static_cast<double>(k) / entries_.at(id).rate_hz;
}

void SensorSchedule::Due(double time_sec, std::vector<SensorFiring>* out) {
  for (size_t i = 0; i < entries_.size(); ++i) {
    Entry& e = entries_[i];
    const double t_k = static_cast<double>(e.next) / e.rate_hz;
    if (time_sec < t_k - kToleranceSec) continue;
    SensorFiring f;
    f.sensor = static_cast<int>(i);
    f.index = e.next;
    f.nominal_time_sec = t_k;
    f.capture_time_sec = time_sec;
    f.delivery_time_sec = time_sec + e.latency_sec;
    out->push_back(f);
    ++e.next;
    // samples that fall inside this step (rate above the physics rate) are skipped
    while (static_cast<double>(e.next) / e.rate_hz <= time_sec + kToleranceSec) {
      ++e.next;
      ++e.skipped;
    }
  }
}

}  // namespace penumbra
