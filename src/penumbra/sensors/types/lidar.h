#pragma once
// the `lidar` sensor type: a scanning or solid-state LiDAR from a preset (sensors/lidar_pattern.h)
// traced in the scene with media and particles (sensors/lidar_scanner.h).

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "penumbra/sensors/lidar_scanner.h"
#include "penumbra/sensors/sensor_type.h"

namespace penumbra {

/// lidar: the preset's pattern with optional overrides and noise (README "sensors").
struct LidarSensorParams {
  static constexpr SensorKind kKind = SensorKind::kLidar;
  static constexpr std::string_view kTypeName = "lidar";
  /// <out>/lidar/<name>/scan_<k>.pcd and index.csv (output/sensor_writers.h).
  static constexpr std::string_view kOutputFolder = "lidar";
  static constexpr SensorAttach kAttach = SensorAttach::kDefaultWorld;
  /// the rate when neither rate_hz nor the preset gives one, Hz (the preset's rate is used).
  static constexpr double kDefaultRateHz = 100.0;
  static constexpr bool kRateFromModel = true;

  std::string preset;                          ///< one of LidarPresetNames(); required
  int columns = 0;                             ///< [1, kMaxLidarBeamsPerScan]; 0 = the preset's
  double min_range_m = -1;                     ///< >= 0; < 0 = the preset's
  double max_range_m = 0;                      ///< >= 0; 0 = the preset's
  std::optional<double> beam_divergence_mrad;  ///< >= 0; nullopt = the preset's
  double reference_reflectivity = 0.1;         ///< (0, 1]
  bool intensity_range_normalized = true;
  bool media = true;  ///< model media and particles
  /// noise: every value in [0, kMaxSensorNoise], dropout_probability in [0, 1].
  double range_stddev_m = 0;
  double dropout_probability = 0;
  double min_intensity = 0;
  double receiver_noise = 0;

  /// sensor-type hooks (sensors/sensor_type.h).
  static std::vector<std::string_view> Keys();
  void Read(const SensorParamReader& r);
  /// the scanner's configuration at `rate_hz` (0 = the preset's).
  /// @throws Error from MakeLidarPattern (options out of range for the preset).
  LidarConfig MakeConfig(double rate_hz) const;
  /// the pattern options of the overrides at `rate_hz` (0 = the preset's).
  LidarPatternOptions PatternOptions(double rate_hz) const;
};

}  // namespace penumbra
