// scene/sensor_description.h: finding a sensor by name and the column labels of its values.

#include "penumbra/scene/sensor_description.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

namespace penumbra {
namespace {

SensorDescription Sensor(const std::string& name, std::vector<std::string> components) {
  SensorDescription s;
  s.name = name;
  s.dim = static_cast<int>(components.size());
  s.components = std::move(components);
  return s;
}

TEST(SensorDescription, FindSensorByNameOrMinusOne) {
  const std::vector<SensorDescription> all = {Sensor("arm/touch", {""}),
                                              Sensor("imu/acc", {"x", "y", "z"})};
  EXPECT_EQ(FindSensor(all, "imu/acc"), 1);
  EXPECT_EQ(FindSensor(all, "arm/touch"), 0);
  EXPECT_EQ(FindSensor(all, "acc"), -1);
  EXPECT_EQ(FindSensor({}, "imu/acc"), -1);
}

TEST(SensorDescription, ValueLabelsCarryTheComponent) {
  EXPECT_EQ(SensorValueLabel(Sensor("range", {""}), 0), "range");
  const SensorDescription q = Sensor("imu/quat", {"w", "x", "y", "z"});
  EXPECT_EQ(SensorValueLabel(q, 0), "imu/quat_w");
  EXPECT_EQ(SensorValueLabel(q, 3), "imu/quat_z");
  EXPECT_THROW(SensorValueLabel(q, 4), std::out_of_range);
}

}  // namespace
}  // namespace penumbra
