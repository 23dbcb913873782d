#include "penumbra/world/ros_config.h"

#include <cctype>
#include <cmath>
#include <set>

#include "penumbra/config/param_reader.h"
#include "penumbra/config/yaml_document.h"
#include "penumbra/core/error.h"
#include "penumbra/core/input_file.h"
#include "penumbra/world/world_config.h"

namespace penumbra {

namespace {

[[noreturn]] void RosFail(const std::string& key, const std::string& problem) {
  throw ConfigError("", 0, key, problem);
}

void CheckTopic(const std::string& key, const std::string& topic) {
  if (!topic.empty() && !IsValidRosName(topic))
    RosFail(key, "'" + topic +
                     "' is not a ROS graph name; expected letters, digits, '_' and single '/' "
                     "(starting with a letter, '/' or '~', not ending in '/')");
}

void CheckFrame(const std::string& key, const std::string& id, bool required) {
  if (id.empty() && !required) return;
  if (!IsValidFrameId(id))
    RosFail(key, "'" + id +
                     "' is not a tf frame id; expected letters, digits, '_', '-', '.' and '/' "
                     "with no leading '/'");
}

}  // namespace

bool IsValidRosName(const std::string& name) {
  if (name.empty() || name == "/" || name.back() == '/') return false;
  const unsigned char first = name[0];
  if (!std::isalpha(first) && first != '/' && first != '~') return false;
  for (size_t i = 1; i < name.size(); ++i) {
    const unsigned char c = name[i];
    if (c == '/') {
      if (name[i - 1] == '/' || name[i - 1] == '~') return false;
      continue;
    }
    if (!std::isalnum(c) && c != '_') return false;
    // a segment starts with a letter or '_'
    if (name[i - 1] == '/' && std::isdigit(c)) return false;
  }
  return true;
}

bool IsValidFrameId(const std::string& id) {
  if (id.empty() || id[0] == '/') return false;
  for (unsigned char c : id)
    if (!std::isalnum(c) && c != '_' && c != '-' && c != '.' && c != '/') return false;
  return true;
}

RosConfig ReadRosConfig(const ParamReader& r) {
  r.ExpectMap({"namespace", "map_frame", "state_rate_hz", "robots", "sensors"});
  RosConfig c;
  if (const auto found = r.Find("namespace")) c.ns = found->String();
  if (const auto found = r.Find("map_frame")) c.map_frame = found->String();
  if (const auto found = r.Find("state_rate_hz")) c.state_rate_hz = found->Double();
  if (r.Has("robots")) {
    const ParamReader robots = r.Child("robots");
    robots.ExpectMapAnyKeys();
    for (auto& [name, e] : robots.Entries()) {
      e.ExpectMap({"base_body", "base_frame", "odom_frame", "namespace"});
      RosRobotConfig rc;
      rc.robot = name;
      if (const auto found = e.Find("base_body")) rc.base_body = found->String();
      if (const auto found = e.Find("base_frame")) rc.base_frame = found->String();
      if (const auto found = e.Find("odom_frame")) rc.odom_frame = found->String();
      if (const auto found = e.Find("namespace")) rc.ns = found->String();
      c.robots.push_back(rc);
    }
  }
  if (r.Has("sensors")) {
    const ParamReader sensors = r.Child("sensors");
    sensors.ExpectMapAnyKeys();
    for (auto& [name, e] : sensors.Entries()) {
      e.ExpectMap({"topic", "frame_id"});
      RosSensorConfig sc;
      sc.sensor = name;
      if (const auto found = e.Find("topic")) sc.topic = found->String();
      if (const auto found = e.Find("frame_id")) sc.frame_id = found->String();
      c.sensors.push_back(sc);
    }
  }
  return c;
}

void RosConfig::ValidateOrThrow() const {
  if (!ns.empty() && ns != "/") CheckTopic("ros.namespace", ns);
  CheckFrame("ros.map_frame", map_frame, true);
  if (!std::isfinite(state_rate_hz) || state_rate_hz <= 0 || state_rate_hz > 1000)
    RosFail("ros.state_rate_hz",
            "got " + FormatNumber(state_rate_hz) + "; expected (0, 1000] per second of sim time");
  std::set<std::string> seen;
  for (const RosRobotConfig& r : robots) {
    const std::string key = "ros.robots." + r.robot;
    if (!seen.insert(r.robot).second) RosFail(key, "listed twice; expected one entry per robot");
    if (r.base_body.find('/') != std::string::npos)
      RosFail(key + ".base_body", "'" + r.base_body +
                                      "'; expected the model-local body name (without \"" +
                                      r.robot + "/\")");
    CheckFrame(key + ".base_frame", r.base_frame, false);
    CheckFrame(key + ".odom_frame", r.odom_frame, false);
    CheckTopic(key + ".namespace", r.ns);
  }
  seen.clear();
  for (const RosSensorConfig& s : sensors) {
    const std::string key = "ros.sensors." + s.sensor;
    if (!seen.insert(s.sensor).second) RosFail(key, "listed twice; expected one entry per sensor");
    CheckTopic(key + ".topic", s.topic);
    CheckFrame(key + ".frame_id", s.frame_id, false);
  }
}

void ValidateRosReferences(const RosConfig& ros, const WorldConfig& world) {
  std::string robots, sensors;
  std::set<std::string> robot_names, sensor_names;
  for (const ModelConfig& m : world.models)
    if (m.is_robot) {
      robot_names.insert(m.name);
      robots += (robots.empty() ? "" : ", ") + m.name;
    }
  for (const CameraConfig& c : world.cameras) {
    sensor_names.insert(c.name);
    sensors += (sensors.empty() ? "" : ", ") + c.name;
  }
  for (const SensorConfig& s : world.sensors)
    if (s.type == "lidar" || s.type == "imu") {
      sensor_names.insert(s.name);
      sensors += (sensors.empty() ? "" : ", ") + s.name;
    }
  for (const RosRobotConfig& r : ros.robots)
    if (!robot_names.count(r.robot))
      RosFail("ros.robots." + r.robot, "'" + r.robot +
                                           "' is not a robot of the world; expected one of: " +
                                           (robots.empty() ? std::string("(none)") : robots));
  for (const RosSensorConfig& s : ros.sensors)
    if (s.sensor.find('/') == std::string::npos && !sensor_names.count(s.sensor))
      RosFail("ros.sensors." + s.sensor,
              "'" + s.sensor + "' is not a camera, LiDAR or IMU of the world; expected one of: " +
                  (sensors.empty() ? std::string("(none)") : sensors) +
                  " (or an MJCF camera \"<model>/<camera>\")");
}

RosConfig LoadRosConfig(const WorldConfig& world) {
  if (world.file.empty()) return RosConfig{};
  const ConfigValue root = ParseYaml(ReadInputFile(world.file, "world file"), world.file);
  if (!root.IsMap() || !root["ros"]) return RosConfig{};
  LineTable lines;
  const ParamReader r(root, world.file, &lines);
  const RosConfig c = ReadRosConfig(r.Child("ros"));
  try {
    c.ValidateOrThrow();
    ValidateRosReferences(c, world);
  } catch (const ConfigError& e) {
    throw ConfigError(world.file, lines.Find(e.key()), e.key(), e.problem());
  }
  return c;
}

}  // namespace penumbra
