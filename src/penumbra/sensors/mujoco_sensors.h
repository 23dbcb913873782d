#pragma once
// reading MuJoCo-native sensors by name from a WorldSnapshot (values from
// WorldSnapshot::sensordata, metadata: the engine-neutral SensorDescription of
// scene/sensor_description.h, which the physics module fills: Simulation::sensor_info()), with
// optional per-sensor Gaussian noise, and CSV column names that carry the unit (e.g.
// "box/acc_x_m_s2", "arm/shoulder_pos_rad", "range_m").

#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "penumbra/scene/sensor_description.h"
#include "penumbra/scene/world_snapshot.h"

namespace penumbra {

/// the MuJoCo sensor names (accelerometer, gyro) of world-file IMU `imu_name`, as
/// compose/imu_injection.h adds them to the composed model: "penumbra_imu/<name>/accel" and
/// "penumbra_imu/<name>/gyro".
std::pair<std::string, std::string> ImuSensorNames(const std::string& imu_name);

/// a unit string as a column-name suffix: "m/s^2" -> "m_s2", "N m" -> "N_m", "1" -> "".
std::string UnitSuffix(const std::string& unit);

/// the values of sensor `s` in `snapshot` (a view into snapshot.sensordata).
/// @throws Error if the snapshot holds fewer values than the sensor's adr + dim.
std::span<const double> MujocoSensorValues(const WorldSnapshot& snapshot,
                                           const SensorDescription& s);

/// a chosen set of MuJoCo sensors, read together.
class MujocoSensorSet {
 public:
  /// `names` = MJCF sensor names (composed, "<model>/<name>"), or empty for every sensor.
  /// @throws Error naming the first unknown sensor and listing the model's sensors.
  MujocoSensorSet(const std::vector<SensorDescription>& all, const std::vector<std::string>& names);

  /// column names, one per value: "<sensor>[_<component>][_<unit suffix>]".
  std::vector<std::string> ColumnNames() const;
  /// appends every value of the set, in column order, to `out`.
  void Read(const WorldSnapshot& snapshot, std::vector<double>* out) const;
  /// number of values.
  int size() const { return size_; }
  const std::vector<SensorDescription>& sensors() const { return sensors_; }

 private:
  std::vector<SensorDescription> sensors_;
  int size_ = 0;
};

}  // namespace penumbra
