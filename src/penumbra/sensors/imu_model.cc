#include "penumbra/sensors/imu_model.h"

#include <cmath>

#include "penumbra/core/error.h"
#include "penumbra/core/rng.h"
#include "penumbra/sensors/sensor_noise.h"

namespace penumbra {

void ImuNoiseConfig::ValidateOrThrow() const {
  const auto check = [](const char* key, double v, const char* unit) {
    if (!(std::isfinite(v) && v >= 0))
      throw Error(std::string("imu noise ") + key + " = " + std::to_string(v) +
                  " is not valid; expected a finite number >= 0 (" + unit + ")");
  };
  check("accel_noise_density", accel_noise_density, "m/s^2/sqrt(Hz)");
  check("accel_random_walk", accel_random_walk, "m/s^3/sqrt(Hz)");
  check("gyro_noise_density", gyro_noise_density, "rad/s/sqrt(Hz)");
  check("gyro_random_walk", gyro_random_walk, "rad/s^2/sqrt(Hz)");
}

const std::vector<std::string>& ImuPresetNames() {
  static const std::vector<std::string> names = {"consumer_mems", "tactical", "ideal"};
  return names;
}

ImuNoiseConfig ImuPreset(const std::string& name) {
  constexpr double kG = 9.80665, kDeg = 3.14159265358979323846 / 180.0;
  const double rw_per_b = std::sqrt(3.0 / 1000.0);
  ImuNoiseConfig c;
  if (name == "consumer_mems") {
    c.accel_noise_density = 175e-6 * kG;
    c.gyro_noise_density = 0.014 * kDeg;
    c.accel_random_walk = 40e-6 * kG * rw_per_b;
    c.gyro_random_walk = 5.0 * kDeg / 3600.0 * rw_per_b;
  } else if (name == "tactical") {
    c.gyro_noise_density = 0.12 * kDeg / 60.0;  // deg/sqrt(h) -> deg/s/sqrt(Hz): / 60
    c.accel_noise_density = 0.008 / 60.0;       // m/s/sqrt(h) -> m/s^2/sqrt(Hz)
    c.gyro_random_walk = 0.8 * kDeg / 3600.0 * rw_per_b;
    c.accel_random_walk = 3.2e-6 * kG * rw_per_b;
  } else if (name != "ideal") {
    std::string names;
    for (const std::string& n : ImuPresetNames()) names += (names.empty() ? "" : ", ") + n;
    throw Error("unknown imu preset '" + name + "'; expected one of: " + names);
  }
  return c;
}

ImuNoiseModel::ImuNoiseModel(ImuNoiseConfig config, double sample_period_sec, uint64_t stream_seed)
    : config_(config), dt_(sample_period_sec), seed_(stream_seed) {
  config_.ValidateOrThrow();
  if (!(std::isfinite(dt_) && dt_ > 0))
    throw Error("imu: sample period " + std::to_string(dt_) + " s; expected > 0");
}

ImuSample ImuNoiseModel::Apply(int64_t k, const ImuSample& truth) {
  Rng rng(HashKeys(seed_, static_cast<uint64_t>(k)));
  const double sa = config_.accel_noise_density / std::sqrt(dt_);
  const double sg = config_.gyro_noise_density / std::sqrt(dt_);
  const double ba = config_.accel_random_walk * std::sqrt(dt_);
  const double bg = config_.gyro_random_walk * std::sqrt(dt_);
  ImuSample out;
  for (int i = 0; i < 3; ++i) {
    out.accel_m_s2[i] = truth.accel_m_s2[i] + accel_bias_[i] + sa * StandardNormal(&rng);
    out.gyro_rad_s[i] = truth.gyro_rad_s[i] + gyro_bias_[i] + sg * StandardNormal(&rng);
  }
  for (int i = 0; i < 3; ++i) {
    accel_bias_[i] += ba * StandardNormal(&rng);
    gyro_bias_[i] += bg * StandardNormal(&rng);
  }
  return out;
}

}  // namespace penumbra
