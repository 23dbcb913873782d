#include "penumbra/scene/sensor_description.h"

namespace penumbra {

int FindSensor(const std::vector<SensorDescription>& sensors, const std::string& name) {
  for (size_t i = 0; i < sensors.size(); ++i)
    if (sensors[i].name == name) return static_cast<int>(i);
  return -1;
}

std::string SensorValueLabel(const SensorDescription& s, int k) {
  const std::string& c = s.components.at(k);
  return c.empty() ? s.name : s.name + "_" + c;
}

}  // namespace penumbra
