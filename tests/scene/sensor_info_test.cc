// scene/sensor_info.h: finding a sensor by name and the column labels of its values.

#include "penumbra/scene/sensor_info.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

namespace penumbra {
namespace {

SensorInfo Sensor(const std::string& name, std::vector<std::string> components) {
  SensorInfo s;
  s.name = name;
  s.dim = static_cast<int>(components.size());
  s.components = std::move(components);
  return s;
}

TEST(SensorInfo, FindSensorByNameOrMinusOne) {
  const std::vector<SensorInfo> all = {Sensor("arm/touch", {""}),
                                       Sensor("imu/acc", {"x", "y", "z"})};
  EXPECT_EQ(FindSensor(all, "imu/acc"), 1);
  EXPECT_EQ(FindSensor(all, "arm/touch"), 0);
  EXPECT_EQ(FindSensor(all, "acc"), -1);
  EXPECT_EQ(FindSensor({}, "imu/acc"), -1);
}

TEST(SensorInfo, ValueLabelsCarryTheComponent) {
  EXPECT_EQ(SensorValueLabel(Sensor("range", {""}), 0), "range");
  const SensorInfo q = Sensor("imu/quat", {"w", "x", "y", "z"});
  EXPECT_EQ(SensorValueLabel(q, 0), "imu/quat_w");
  EXPECT_EQ(SensorValueLabel(q, 3), "imu/quat_z");
  EXPECT_THROW(SensorValueLabel(q, 4), std::out_of_range);
}

}  // namespace
}  // namespace penumbra
