#pragma once
// the `mujoco` sensor type: the values of MJCF sensors of the composed model
// (sensors/mujoco_sensors.h), with optional Gaussian noise.

#include <string>
#include <string_view>
#include <vector>

#include "penumbra/sensors/sensor_type.h"

namespace penumbra {

/// mujoco: a set of MJCF sensors (README "sensors").
struct MujocoSensorParams {
  static constexpr SensorKind kKind = SensorKind::kMujoco;
  static constexpr std::string_view kTypeName = "mujoco";
  /// <out>/sensors/<name>.csv (output/sensor_writers.h).
  static constexpr std::string_view kOutputFolder = "sensors";
  static constexpr SensorAttach kAttach = SensorAttach::kNone;
  static constexpr double kDefaultRateHz = 100.0;
  static constexpr bool kRateFromModel = false;

  /// MJCF sensor names, composed ("<robot>/<sensor>" under a robot); empty = all.
  std::vector<std::string> sensors;
  double stddev = 0;  ///< Gaussian noise added to every value, [0, kMaxSensorNoise]

  /// sensor-type hooks (sensors/sensor_type.h).
  static std::vector<std::string_view> Keys();
  void Read(const SensorParamReader& r);
};

}  // namespace penumbra
