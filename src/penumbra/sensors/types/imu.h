#pragma once
// the `imu` sensor type: an accelerometer and gyro pair at a body or site (compose/
// imu_injection.h adds them to the model) with the noise of a preset (sensors/imu_model.h).

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "penumbra/sensors/imu_model.h"
#include "penumbra/sensors/sensor_type.h"

namespace penumbra {

/// imu: a preset's noise with optional overrides (README "sensors").
struct ImuSensorParams {
  static constexpr SensorKind kKind = SensorKind::kImu;
  static constexpr std::string_view kTypeName = "imu";
  /// <out>/imu/<name>.csv and <name>_truth.csv (output/sensor_writers.h).
  static constexpr std::string_view kOutputFolder = "imu";
  static constexpr SensorAttach kAttach = SensorAttach::kRequired;
  static constexpr double kDefaultRateHz = 200.0;
  static constexpr bool kRateFromModel = false;

  std::string preset = "consumer_mems";  ///< one of ImuPresetNames()
  /// noise overrides of the preset's values, each in [0, kMaxSensorNoise]; nullopt = the
  /// preset's (units of ImuNoiseConfig).
  std::optional<double> accel_noise_density;
  std::optional<double> accel_random_walk;
  std::optional<double> gyro_noise_density;
  std::optional<double> gyro_random_walk;

  /// sensor-type hooks (sensors/sensor_type.h).
  static std::vector<std::string_view> Keys();
  void Read(const SensorParamReader& r);
  /// the noise model's configuration: the preset with the overrides.
  ImuNoiseConfig MakeNoise() const;
};

}  // namespace penumbra
