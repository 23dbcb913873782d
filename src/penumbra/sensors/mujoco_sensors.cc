#include "penumbra/sensors/mujoco_sensors.h"

#include "penumbra/core/error.h"

namespace penumbra {

std::pair<std::string, std::string> ImuSensorNames(const std::string& imu_name) {
  return {"penumbra_imu/" + imu_name + "/accel", "penumbra_imu/" + imu_name + "/gyro"};
}

std::string UnitSuffix(const std::string& unit) {
  if (unit == "1" || unit.empty()) return "";
  std::string out;
  for (char c : unit) {
    if (c == '/' || c == ' ') {
      if (!out.empty() && out.back() != '_') out += '_';
    } else if (c == '^') {
      continue;
    } else if ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9')) {
      out += c;
    } else if (!out.empty() && out.back() != '_') {
      out += '_';
    }
  }
  while (!out.empty() && out.back() == '_') out.pop_back();
  return out;
}

std::span<const double> MujocoSensorValues(const WorldSnapshot& snapshot,
                                           const SensorDescription& s) {
  if (s.adr < 0 || static_cast<size_t>(s.adr + s.dim) > snapshot.sensordata.size())
    throw Error("MuJoCo sensor '" + s.name + "': the snapshot holds " +
                std::to_string(snapshot.sensordata.size()) + " sensor values; expected at least " +
                std::to_string(s.adr + s.dim));
  return {snapshot.sensordata.data() + s.adr, static_cast<size_t>(s.dim)};
}

MujocoSensorSet::MujocoSensorSet(const std::vector<SensorDescription>& all,
                                 const std::vector<std::string>& names) {
  if (names.empty()) {
    sensors_ = all;
  } else {
    for (const std::string& n : names) {
      const int i = FindSensor(all, n);
      if (i < 0) {
        std::string list;
        for (const SensorDescription& s : all) list += (list.empty() ? "" : ", ") + s.name;
        throw Error("no MuJoCo sensor named '" + n +
                    "'; the model has: " + (list.empty() ? std::string("none") : list));
      }
      sensors_.push_back(all[i]);
    }
  }
  for (const SensorDescription& s : sensors_) size_ += s.dim;
}

std::vector<std::string> MujocoSensorSet::ColumnNames() const {
  std::vector<std::string> cols;
  for (const SensorDescription& s : sensors_) {
    const std::string unit = UnitSuffix(s.unit);
    for (int k = 0; k < s.dim; ++k) {
      std::string c = SensorValueLabel(s, k);
      if (c.empty()) c = "sensor" + std::to_string(s.id);
      if (!unit.empty()) c += "_" + unit;
      cols.push_back(c);
    }
  }
  return cols;
}

void MujocoSensorSet::Read(const WorldSnapshot& snapshot, std::vector<double>* out) const {
  for (const SensorDescription& s : sensors_) {
    const std::span<const double> v = MujocoSensorValues(snapshot, s);
    out->insert(out->end(), v.begin(), v.end());
  }
}

}  // namespace penumbra
