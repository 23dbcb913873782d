#include "penumbra/world/metrics_config.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "penumbra/config/param_reader.h"
#include "penumbra/core/error.h"
#include "penumbra/core/text_match.h"
#include "penumbra/scene/scene_limits.h"
#include "penumbra/world/world_validation.h"

namespace penumbra {
namespace {

struct KindEntry {
  MetricKind kind;
  std::string_view name;
};
constexpr KindEntry kKinds[] = {
    {MetricKind::kBodyPose, "body_pose"},
    {MetricKind::kBodyTwist, "body_twist"},
    {MetricKind::kJointPosition, "joint_position"},
    {MetricKind::kJointVelocity, "joint_velocity"},
    {MetricKind::kJointTorque, "joint_torque"},
    {MetricKind::kDistance, "distance"},
    {MetricKind::kSensor, "sensor"},
    {MetricKind::kTrackingError, "tracking_error"},
    {MetricKind::kContacts, "contacts"},
};

std::vector<std::string_view> KindNames() {
  std::vector<std::string_view> names;
  for (const KindEntry& k : kKinds) names.push_back(k.name);
  return names;
}

// the keys an entry of `kind` takes besides name, type and rate_hz
std::vector<std::string_view> KindKeys(MetricKind kind) {
  switch (kind) {
    case MetricKind::kBodyPose:
    case MetricKind::kBodyTwist:
      return {"bodies"};
    case MetricKind::kJointPosition:
    case MetricKind::kJointVelocity:
    case MetricKind::kJointTorque:
      return {"joints"};
    case MetricKind::kDistance:
      return {"body", "to_body", "to_point"};
    case MetricKind::kSensor:
      return {"sensors"};
    case MetricKind::kTrackingError:
      return {"robot"};
    case MetricKind::kContacts:
      return {"min_force_N",   "debounce_sec", "between",  "exclude",
              "self_contacts", "pair",         "detect_hz"};
  }
  return {};
}

std::vector<std::string> Names(const ParamReader& r) {
  std::vector<std::string> out;
  for (const ParamReader& e : r.List()) out.push_back(e.String());
  return out;
}

std::vector<ContactPairRule> ReadRules(const ParamReader& r) {
  std::vector<ContactPairRule> rules;
  for (const ParamReader& e : r.List()) {
    e.ExpectMap({"a", "b"});
    ContactPairRule rule;
    if (const auto found = e.Find("a")) rule.a = found->String();
    if (const auto found = e.Find("b")) rule.b = found->String();
    rules.push_back(rule);
  }
  return rules;
}

MetricConfig ReadEntry(const ParamReader& r) {
  r.ExpectMapAnyKeys();
  MetricConfig m;
  m.name = r.Child("name").String();
  const std::string type = r.Child("type").Enum(KindNames());
  for (const KindEntry& k : kKinds)
    if (k.name == type) m.kind = k.kind;
  std::vector<std::string_view> keys = {"name", "type", "rate_hz"};
  const std::vector<std::string_view> own = KindKeys(m.kind);
  keys.insert(keys.end(), own.begin(), own.end());
  for (const auto& [key, child] : r.Entries()) {
    if (std::find(keys.begin(), keys.end(), key) == keys.end())
      child.Fail("does not apply to a " + type + " metric; expected one of: " + JoinNames(keys));
  }
  if (const auto found = r.Find("rate_hz")) m.rate_hz = found->Double();
  switch (m.kind) {
    case MetricKind::kBodyPose:
    case MetricKind::kBodyTwist:
      m.bodies = Names(r.Child("bodies"));
      break;
    case MetricKind::kJointPosition:
    case MetricKind::kJointVelocity:
    case MetricKind::kJointTorque:
      m.joints = Names(r.Child("joints"));
      break;
    case MetricKind::kDistance:
      m.body = r.Child("body").String();
      if (r.Has("to_body") == r.Has("to_point"))
        r.Fail("a distance metric needs exactly one of to_body and to_point");
      if (const auto found = r.Find("to_body")) m.to_body = found->String();
      if (const auto found = r.Find("to_point")) m.to_point_m = found->Vector3();
      break;
    case MetricKind::kSensor:
      m.sensors = Names(r.Child("sensors"));
      break;
    case MetricKind::kTrackingError:
      m.robot = r.Child("robot").String();
      break;
    case MetricKind::kContacts:
      if (const auto found = r.Find("min_force_N")) m.min_force_N = found->Double();
      if (const auto found = r.Find("debounce_sec")) m.debounce_sec = found->Double();
      if (const auto found = r.Find("between")) m.between = ReadRules(*found);
      if (const auto found = r.Find("exclude")) m.exclude = ReadRules(*found);
      if (const auto found = r.Find("self_contacts")) m.self_contacts = found->Bool();
      if (const auto found = r.Find("pair")) m.geom_pairs = found->Enum({"body", "geom"}) == "geom";
      if (const auto found = r.Find("detect_hz")) m.detect_hz = found->Double();
      break;
  }
  return m;
}

[[noreturn]] void Fail(const std::string& key, const std::string& problem) {
  throw ConfigError("", 0, key, problem);
}

void CheckNames(const std::string& key, const std::vector<std::string>& names, const char* what) {
  if (names.empty()) Fail(key, std::string("empty list; expected at least one ") + what);
  for (size_t i = 0; i < names.size(); ++i)
    if (names[i].empty())
      Fail(key + "[" + std::to_string(i) + "]", std::string("empty; expected a ") + what);
}

}  // namespace

std::string_view MetricKindName(MetricKind kind) {
  for (const KindEntry& k : kKinds)
    if (k.kind == kind) return k.name;
  return "?";
}

void MetricsConfig::ValidateOrThrow() const {
  auto rate_ok = [](double v) { return std::isfinite(v) && v > 0 && v <= 10000; };
  if (!rate_ok(rate_hz))
    Fail("metrics.rate_hz", "got " + FormatNumber(rate_hz) + "; expected (0, 10000] Hz");
  std::map<std::string, size_t> seen;
  for (size_t i = 0; i < series.size(); ++i) {
    const MetricConfig& m = series[i];
    const std::string key = "metrics.series[" + std::to_string(i) + "]";
    if (auto problem = NameLengthProblem(m.name)) Fail(key + ".name", *problem);
    if (!IsValidWorldName(m.name))
      Fail(key + ".name", "'" + m.name +
                              "' is not a valid metric name; expected letters, digits, '_' or "
                              "'-' (it names the CSV file)");
    if (auto [it, fresh] = seen.emplace(m.name, i); !fresh)
      Fail(key + ".name", "duplicate name '" + m.name + "' (also metrics.series[" +
                              std::to_string(it->second) + "]); expected unique names");
    if (m.rate_hz && !rate_ok(*m.rate_hz))
      Fail(key + ".rate_hz", "got " + FormatNumber(*m.rate_hz) + "; expected (0, 10000] Hz");
    switch (m.kind) {
      case MetricKind::kBodyPose:
      case MetricKind::kBodyTwist:
        CheckNames(key + ".bodies", m.bodies, "body name or glob");
        break;
      case MetricKind::kJointPosition:
      case MetricKind::kJointVelocity:
      case MetricKind::kJointTorque:
        CheckNames(key + ".joints", m.joints, "joint name or glob");
        break;
      case MetricKind::kSensor:
        CheckNames(key + ".sensors", m.sensors, "MJCF sensor name or glob");
        break;
      case MetricKind::kDistance:
        if (m.body.empty()) Fail(key + ".body", "required; expected a body name");
        if (m.to_body.empty() == !m.to_point_m.has_value())
          Fail(key, "a distance metric needs exactly one of to_body and to_point");
        if (m.to_point_m &&
            !(m.to_point_m->allFinite() && m.to_point_m->cwiseAbs().maxCoeff() <= kMaxPositionM))
          Fail(key + ".to_point", "expected 3 numbers, each in [-1e+05, 1e+05] (m)");
        break;
      case MetricKind::kTrackingError:
        if (m.robot.empty()) Fail(key + ".robot", "required; expected a robot's name");
        break;
      case MetricKind::kContacts:
        // a force no contact reaches, or a debounce longer than any run, counts nothing
        if (!(m.min_force_N >= 0 && m.min_force_N <= 1e9))
          Fail(key + ".min_force_N",
               "got " + FormatNumber(m.min_force_N) + "; expected a number in [0, 1e+09] (N)");
        if (!(m.debounce_sec >= 0 && m.debounce_sec <= kMaxDurationSec))
          Fail(key + ".debounce_sec",
               "got " + FormatNumber(m.debounce_sec) + "; expected a number in [0, 1e+06] (s)");
        if (!std::isfinite(m.detect_hz) || m.detect_hz < 0 || m.detect_hz > 100000)
          Fail(key + ".detect_hz", "got " + FormatNumber(m.detect_hz) +
                                       "; expected [0, 100000] Hz (0 = every physics step)");
        for (const auto* rules : {&m.between, &m.exclude}) {
          const std::string list = key + (rules == &m.between ? ".between" : ".exclude");
          for (size_t j = 0; j < rules->size(); ++j) {
            if ((*rules)[j].a.empty() || (*rules)[j].b.empty())
              Fail(list + "[" + std::to_string(j) + "]",
                   "empty pattern; expected globs over geom or body names (\"*\" = any)");
          }
        }
        break;
    }
  }
}

MetricsConfig ReadMetrics(const ParamReader& r) {
  r.ExpectMap({"rate_hz", "series"});
  MetricsConfig c;
  if (const auto found = r.Find("rate_hz")) c.rate_hz = found->Double();
  if (r.Has("series"))
    for (const ParamReader& e : r.Child("series").List()) c.series.push_back(ReadEntry(e));
  return c;
}

}  // namespace penumbra
