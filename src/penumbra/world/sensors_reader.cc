#include "penumbra/world/sensors_reader.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <set>
#include <string_view>
#include <variant>

#include "penumbra/config/param_reader.h"
#include "penumbra/core/error.h"
#include "penumbra/core/text_match.h"
#include "penumbra/scene/scene_limits.h"

namespace penumbra {
namespace {

std::string Prefixed(const std::string& robot, const std::string& name) {
  if (robot.empty() || name == "world") return name;
  return robot + "/" + name;
}

// the sensor registry's reader (sensors/sensor_type.h) over one node of the entry (config/)
class WorldSensorParamReader : public SensorParamReader {
 public:
  WorldSensorParamReader(ParamReader node, std::string robot)
      : node_(std::move(node)), robot_(std::move(robot)) {}

  bool Has(std::string_view k) const override { return node_.Has(k); }
  double Double(std::string_view k) const override { return node_.Child(k).Double(); }
  int Integer(std::string_view k) const override { return node_.Child(k).Int(); }
  bool Boolean(std::string_view k) const override { return node_.Child(k).Bool(); }
  std::string Enum(std::string_view k, const std::vector<std::string_view>& valid) const override {
    return node_.Child(k).Enum(valid);
  }
  std::vector<std::string> Names(std::string_view k) const override {
    std::vector<std::string> out;
    for (const ParamReader& e : node_.Child(k).List()) out.push_back(Prefixed(robot_, e.String()));
    return out;
  }
  std::unique_ptr<SensorParamReader> Map(std::string_view k,
                                         const std::vector<std::string_view>& keys) const override {
    ParamReader child = node_.Child(k);
    child.ExpectMap(keys);
    return std::make_unique<WorldSensorParamReader>(std::move(child), robot_);
  }
  [[noreturn]] void Fail(std::string_view k, const std::string& problem) const override {
    if (k.empty()) node_.Fail(problem);
    node_.Child(k).Fail(problem);
  }

 private:
  ParamReader node_;
  std::string robot_;
};

SensorConfig ReadSensorFields(const ParamReader& r, const std::string& robot, SensorConfig s);

// every error after the name names the sensor: "sensor '<name>': <problem>"
SensorConfig ReadSensor(const ParamReader& r, const std::string& robot) {
  r.ExpectMapAnyKeys();
  SensorConfig s;
  s.name = r.Child("name").String();
  const std::string name = s.name;
  try {
    return ReadSensorFields(r, robot, std::move(s));
  } catch (const ConfigError& e) {
    const std::string what = e.what();
    const std::string tag = "sensor '" + name + "'";
    if (what.find(tag) != std::string::npos) throw;
    const size_t at = e.key().empty() ? std::string::npos : what.find(e.key() + ": ");
    const std::string problem =
        at == std::string::npos ? what : what.substr(at + e.key().size() + 2);
    throw ConfigError(e.file(), e.line(), e.key(), tag + ": " + problem);
  }
}

SensorConfig ReadSensorFields(const ParamReader& r, const std::string& robot, SensorConfig s) {
  s.line = r.line();
  s.key = r.path();
  s.robot = robot;
  if (auto problem = NameLengthProblem(s.name)) r.Child("name").Fail(*problem);
  const bool control = std::any_of(s.name.begin(), s.name.end(), [](char ch) {
    return static_cast<unsigned char>(ch) < 0x20 || ch == 0x7F;
  });
  if (s.name.empty() || s.name.find_first_of("/\\ \t") != std::string::npos || control ||
      s.name == "." || s.name == "..")
    r.Child("name").Fail("'" + s.name +
                         "' is not a valid sensor name; expected a non-empty "
                         "name without '/', '\\', spaces or control characters, not '.' or "
                         "'..' (it names output files)");
  // the type's keys and parameters come from the sensor registry (sensors/sensor_types.h)
  std::vector<std::string_view> types;
  for (const SensorTypeInfo& t : kSensorTypes) types.push_back(t.name);
  const SensorKind kind = *SensorKindFromName(r.Child("type").Enum(types));
  const SensorTypeInfo& type = Info(kind);
  s.params = DefaultSensorParams(kind);
  std::vector<std::string_view> keys = {"name", "type", "rate_hz", "latency_sec"};
  if (type.attach != SensorAttach::kNone) keys.insert(keys.end(), {"body", "site", "pose"});
  const std::vector<std::string_view> type_keys =
      std::visit([](const auto& p) { return std::decay_t<decltype(p)>::Keys(); }, s.params);
  keys.insert(keys.end(), type_keys.begin(), type_keys.end());
  r.ExpectMap(keys);
  const std::string sensor = "sensor '" + s.name + "': ";
  if (r.Has("rate_hz")) {
    const ParamReader c = r.Child("rate_hz");
    s.rate_hz = c.Double();
    if (!(*s.rate_hz > 0))
      c.Fail(sensor + "got " + FormatNumber(*s.rate_hz) + "; expected a rate > 0 (Hz)");
  }
  const WorldSensorParamReader reader(r, robot);
  if (r.Has("latency_sec")) s.latency_sec = reader.NonNegative("latency_sec", "s", 3600);
  if (r.Has("body")) s.body = Prefixed(robot, r.Child("body").String());
  if (r.Has("site")) s.site = Prefixed(robot, r.Child("site").String());
  if (!s.body.empty() && !s.site.empty())
    r.Child("site").Fail(sensor + "both body and site are set; expected one of them");
  if (type.attach == SensorAttach::kRequired && s.body.empty() && s.site.empty())
    r.Fail(sensor +
           (std::string_view("aeiou").find(type.name.front()) == std::string_view::npos ? "a "
                                                                                        : "an ") +
           std::string(type.name) + " needs 'body' or 'site' to attach to");
  if (type.attach == SensorAttach::kDefaultWorld && s.body.empty() && s.site.empty())
    s.body = "world";
  if (r.Has("pose")) {
    const ParamReader p = r.Child("pose");
    p.ExpectMap({"xyz", "rpy_deg"});
    if (p.Has("xyz")) {
      const ParamReader c = p.Child("xyz");
      s.xyz = c.Vector3();
      if (!(s.xyz.cwiseAbs().maxCoeff() <= kMaxPositionM))
        c.Fail(sensor + "got [" + FormatNumber(s.xyz.x()) + ", " + FormatNumber(s.xyz.y()) + ", " +
               FormatNumber(s.xyz.z()) + "]; expected each of the 3 numbers in [" +
               FormatNumber(-kMaxPositionM) + ", " + FormatNumber(kMaxPositionM) + "] (m)");
    }
    if (const auto found = p.Find("rpy_deg")) {
      s.rpy_deg = found->Vector3();
      // one turn holds every rotation, as for the world file's poses
      if (!(s.rpy_deg.cwiseAbs().maxCoeff() <= 360))
        found->Fail(sensor + "got [" + FormatNumber(s.rpy_deg.x()) + ", " +
                    FormatNumber(s.rpy_deg.y()) + ", " + FormatNumber(s.rpy_deg.z()) +
                    "]; expected each of the 3 numbers in [-360, 360] (deg)");
    }
  }
  std::visit([&](auto& p) { p.Read(reader); }, s.params);
  return s;
}

}  // namespace

std::vector<SensorConfig> ReadSensors(const ParamReader& list, const std::string& file,
                                      const std::string& robot) {
  std::vector<SensorConfig> out;
  for (const ParamReader& e : list.List()) {
    out.push_back(ReadSensor(e, robot));
    out.back().file = file;
  }
  return out;
}

void ValidateSensorNames(const std::vector<SensorConfig>& sensors) {
  std::set<std::string> seen;
  for (const SensorConfig& s : sensors)
    if (!seen.insert(s.name).second)
      throw ConfigError(s.file, s.line, s.key + ".name",
                        "sensor name '" + s.name + "' is used twice; expected unique names");
}

}  // namespace penumbra
