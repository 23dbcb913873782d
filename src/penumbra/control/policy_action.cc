#include "penumbra/control/policy_action.h"

#include <cmath>

#include "penumbra/config/config_value.h"

namespace penumbra {
namespace {}  // namespace

const char* PolicyActionKindName(PolicyActionKind kind) {
  switch (kind) {
    case PolicyActionKind::kJointPosition:
      return "joint_position";
    case PolicyActionKind::kJointVelocity:
      return "joint_velocity";
    case PolicyActionKind::kJointTorque:
      return "joint_torque";
  }
  return "?";
}

void PolicyActionParams::ParseOver(ControllerParams& p, const ConfigValue& n,
                                   const std::string& key, const std::string& prefix) {
  if (!n.IsMap())
    p.Fail(key, "got " + DescribeParamNode(n) +
                    "; expected {type: joint_position | joint_velocity | joint_torque, scale, "
                    "clip, kp, kd, actuators}");
  for (const auto& kv : n.pairs()) {
    const std::string k = kv.first.Scalar();
    if (k != "type" && k != "scale" && k != "clip" && k != "kp" && k != "kd" && k != "actuators")
      p.Fail(key + "." + k, "unknown field; expected only type, scale, clip, kp, kd, actuators");
  }
  if (n["type"]) {
    const std::string t = n["type"].IsScalar() ? n["type"].Scalar() : "";
    bool found = false;
    for (PolicyActionKind k : {PolicyActionKind::kJointPosition, PolicyActionKind::kJointVelocity,
                               PolicyActionKind::kJointTorque})
      if (t == PolicyActionKindName(k)) {
        kind = k;
        found = true;
      }
    if (!found)
      p.Fail(key + ".type", "got " + DescribeParamNode(n["type"]) +
                                "; expected joint_position, joint_velocity or joint_torque");
  }
  if (n["scale"])
    scale = ParamNumbersAt(p, n["scale"], key + ".scale", "a finite number",
                           [](double) { return true; });
  if (n["clip"]) {
    const double c = ParamNumberAt(p, n["clip"], key + ".clip", "a number > 0");
    if (!(c > 0)) p.Fail(key + ".clip", "got " + n["clip"].Scalar() + "; expected a number > 0");
    clip = c;
  }
  if (n["kp"])
    kp = ParamNumbersAt(p, n["kp"], key + ".kp", "a gain >= 0 (N m/rad)",
                        [](double v) { return v >= 0; });
  if (n["kd"])
    kd = ParamNumbersAt(p, n["kd"], key + ".kd", "a gain >= 0 (N m s/rad)",
                        [](double v) { return v >= 0; });
  if (n["actuators"]) {
    const ConfigValue a = n["actuators"];
    if (!a.IsSequence() || a.size() == 0)
      p.Fail(key + ".actuators",
             "got " + DescribeParamNode(a) + "; expected a list of actuator names");
    actuators.clear();
    for (size_t i = 0; i < a.size(); ++i) {
      if (!a[i].IsScalar() || a[i].Scalar().empty())
        p.Fail(key + ".actuators[" + std::to_string(i) + "]",
               "got " + DescribeParamNode(a[i]) + "; expected an actuator name");
      actuators.push_back(prefix + a[i].Scalar());
    }
  }
}

}  // namespace penumbra
