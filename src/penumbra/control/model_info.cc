#include "penumbra/control/model_info.h"

namespace penumbra {

const char* ActuatorDriveName(ActuatorDrive drive) {
  switch (drive) {
    case ActuatorDrive::kMotor:
      return "motor";
    case ActuatorDrive::kPositionServo:
      return "position servo";
    case ActuatorDrive::kVelocityServo:
      return "velocity servo";
    case ActuatorDrive::kOther:
      break;
  }
  return "general actuator";
}

const char* ModelObjectName(ModelObject kind) {
  switch (kind) {
    case ModelObject::kBody:
      return "body";
    case ModelObject::kJoint:
      return "joint";
    case ModelObject::kActuator:
      return "actuator";
    case ModelObject::kSensor:
      return "sensor";
    case ModelObject::kSite:
      return "site";
    case ModelObject::kKey:
      return "keyframe";
  }
  return "object";
}

std::vector<std::string> ModelInfo::Names(ModelObject kind) const {
  std::vector<std::string> out;
  switch (kind) {
    case ModelObject::kBody:
      return body_names;
    case ModelObject::kSite:
      return site_names;
    case ModelObject::kJoint:
      for (const auto& j : joints) out.push_back(j.name);
      break;
    case ModelObject::kActuator:
      for (const auto& a : actuators) out.push_back(a.name);
      break;
    case ModelObject::kSensor:
      for (const auto& s : sensors) out.push_back(s.name);
      break;
    case ModelObject::kKey:
      for (const auto& k : keys) out.push_back(k.name);
      break;
  }
  return out;
}

int ModelInfo::Find(ModelObject kind, const std::string& name) const {
  if (name.empty()) return -1;
  auto find = [&](const auto& v, auto get) {
    for (size_t i = 0; i < v.size(); ++i)
      if (get(v[i]) == name) return static_cast<int>(i);
    return -1;
  };
  auto self = [](const std::string& s) -> const std::string& { return s; };
  auto named = [](const auto& x) -> const std::string& { return x.name; };
  switch (kind) {
    case ModelObject::kBody:
      return find(body_names, self);
    case ModelObject::kSite:
      return find(site_names, self);
    case ModelObject::kJoint:
      return find(joints, named);
    case ModelObject::kActuator:
      return find(actuators, named);
    case ModelObject::kSensor:
      return find(sensors, named);
    case ModelObject::kKey:
      return find(keys, named);
  }
  return -1;
}

}  // namespace penumbra
