#include "penumbra/sensors/sensor_type.h"

#include <charconv>

namespace penumbra {

std::string SensorNumber(double v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof(buf), v);
  return std::string(buf, r.ptr);
}

double SensorParamReader::NonNegative(std::string_view k, const std::string& unit,
                                      double max) const {
  const double v = Double(k);
  if (!(v >= 0 && v <= max))
    Fail(k, "got " + SensorNumber(v) + "; expected a number in [0, " + SensorNumber(max) + "] (" +
                unit + ")");
  return v;
}

double SensorParamReader::Noise(std::string_view k) const {
  const double v = Double(k);
  if (!(v >= 0 && v <= kMaxSensorNoise))
    Fail(k, "got " + SensorNumber(v) +
                "; expected a noise value >= 0 and <= " + SensorNumber(kMaxSensorNoise));
  return v;
}

}  // namespace penumbra
