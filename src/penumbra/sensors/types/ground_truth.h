#pragma once
// the `ground_truth` sensor type: the poses of bodies of the composed model and, optionally,
// its contacts, at the sensor's rate.

#include <string>
#include <string_view>
#include <vector>

#include "penumbra/sensors/sensor_type.h"

namespace penumbra {

/// ground_truth: body poses and contacts (README "sensors").
struct GroundTruthSensorParams {
  static constexpr SensorKind kKind = SensorKind::kGroundTruth;
  static constexpr std::string_view kTypeName = "ground_truth";
  /// <out>/ground_truth/<name>.csv and <name>_contacts.csv (output/sensor_writers.h).
  static constexpr std::string_view kOutputFolder = "ground_truth";
  static constexpr SensorAttach kAttach = SensorAttach::kNone;
  static constexpr double kDefaultRateHz = 100.0;
  static constexpr bool kRateFromModel = false;

  /// body names, composed ("<robot>/<body>" under a robot); empty = every named body.
  std::vector<std::string> bodies;
  bool contacts = true;  ///< also write <name>_contacts.csv

  /// sensor-type hooks (sensors/sensor_type.h).
  static std::vector<std::string_view> Keys();
  void Read(const SensorParamReader& r);
};

}  // namespace penumbra
