#include "penumbra/control/policy_action.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "penumbra/config/config_value.h"
#include "penumbra/core/error.h"

namespace penumbra {
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
    scale = ParamNumbersAt(p, n["scale"], key + ".scale", "a number with |scale| <= 1e4",
                           [](double v) { return std::abs(v) <= kPolicyMaxActionScale; });
  if (n["clip"]) {
    const double c = ParamNumberAt(p, n["clip"], key + ".clip", "a number in (0, 1e6]");
    if (!(c > 0) || c > kPolicyMaxAbsAction)
      p.Fail(key + ".clip", "got " + n["clip"].Scalar() + "; expected a number in (0, 1e6]");
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

void ProcessPolicyOutputs(std::span<const float> raw, const std::optional<double>& clip,
                          int64_t step, double time_sec, const std::vector<std::string>& joints,
                          const std::string& label, std::span<double> action) {
  if (raw.size() != action.size())
    throw Error(label + ": the policy returned " + std::to_string(raw.size()) +
                " outputs; expected " + std::to_string(action.size()));
  for (size_t j = 0; j < raw.size(); ++j) {
    const double v = raw[j];
    if (!(std::abs(v) <= kPolicyMaxAbsAction)) {
      std::ostringstream m;
      m << label << ": policy step " << step << " (t = " << time_sec << " s): output " << j;
      if (j < joints.size()) m << " (joint '" << joints[j] << "')";
      m << " is " << v << "; expected a finite value with |value| <= " << kPolicyMaxAbsAction
        << " (kPolicyMaxAbsAction, docs/policies.md)";
      throw Error(m.str());
    }
    action[j] = clip ? std::clamp(v, -*clip, *clip) : v;
  }
}

}  // namespace penumbra
