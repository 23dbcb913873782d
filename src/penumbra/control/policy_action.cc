#include "penumbra/control/policy_action.h"

#include <yaml-cpp/yaml.h>

#include <cmath>

namespace penumbra {
namespace {

std::string DescribeActionNode(const YAML::Node& n) {
  if (n.IsScalar()) return "'" + n.Scalar() + "'";
  if (n.IsSequence()) return "a list of " + std::to_string(n.size()) + " items";
  if (n.IsMap()) return "a mapping";
  return "nothing";
}

double ActionNumber(ControllerParams& p, const YAML::Node& n, const std::string& key,
                    const std::string& expected) {
  double v = 0;
  bool ok = n.IsScalar();
  if (ok) {
    try {
      v = n.as<double>();
    } catch (const YAML::Exception&) {
      ok = false;
    }
  }
  if (!ok || !std::isfinite(v))
    p.Fail(key, "got " + DescribeActionNode(n) + "; expected " + expected);
  return v;
}

std::vector<double> ActionNumbers(ControllerParams& p, const YAML::Node& n, const std::string& key,
                                  const std::string& expected, bool non_negative) {
  std::vector<double> out;
  const bool list = n.IsSequence();
  if (list && n.size() == 0) p.Fail(key, "got an empty list; expected " + expected);
  for (size_t i = 0; i < (list ? n.size() : 1); ++i) {
    const std::string k = list ? key + "[" + std::to_string(i) + "]" : key;
    const YAML::Node e = list ? n[i] : n;
    const double v = ActionNumber(p, e, k, expected);
    if (non_negative && v < 0) p.Fail(k, "got " + e.Scalar() + "; expected " + expected);
    out.push_back(v);
  }
  return out;
}

}  // namespace

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

void PolicyActionParams::ParseOver(ControllerParams& p, const YAML::Node& n, const std::string& key,
                                   const std::string& prefix) {
  if (!n.IsMap())
    p.Fail(key, "got " + DescribeActionNode(n) +
                    "; expected {type: joint_position | joint_velocity | joint_torque, scale, "
                    "clip, kp, kd, actuators}");
  for (const auto& kv : n) {
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
      p.Fail(key + ".type", "got " + DescribeActionNode(n["type"]) +
                                "; expected joint_position, joint_velocity or joint_torque");
  }
  if (n["scale"]) scale = ActionNumbers(p, n["scale"], key + ".scale", "a finite number", false);
  if (n["clip"]) {
    const double c = ActionNumber(p, n["clip"], key + ".clip", "a number > 0");
    if (!(c > 0)) p.Fail(key + ".clip", "got " + n["clip"].Scalar() + "; expected a number > 0");
    clip = c;
  }
  if (n["kp"]) kp = ActionNumbers(p, n["kp"], key + ".kp", "a gain >= 0 (N m/rad)", true);
  if (n["kd"]) kd = ActionNumbers(p, n["kd"], key + ".kd", "a gain >= 0 (N m s/rad)", true);
  if (n["actuators"]) {
    const YAML::Node a = n["actuators"];
    if (!a.IsSequence() || a.size() == 0)
      p.Fail(key + ".actuators",
             "got " + DescribeActionNode(a) + "; expected a list of actuator names");
    actuators.clear();
    for (size_t i = 0; i < a.size(); ++i) {
      if (!a[i].IsScalar() || a[i].Scalar().empty())
        p.Fail(key + ".actuators[" + std::to_string(i) + "]",
               "got " + DescribeActionNode(a[i]) + "; expected an actuator name");
      actuators.push_back(prefix + a[i].Scalar());
    }
  }
}

}  // namespace penumbra
