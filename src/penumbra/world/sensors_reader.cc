#include "penumbra/world/sensors_reader.h"

#include <algorithm>
#include <cmath>
#include <set>

#include "penumbra/config/param_reader.h"
#include "penumbra/core/error.h"
#include "penumbra/core/text_match.h"
#include "penumbra/scene/scene_limits.h"

namespace penumbra {
namespace {

// the presets of sensors/lidar_pattern.h and sensors/imu_model.h (the world module does not
// link the sensors module; tests/sensors checks that both lists agree)
const std::vector<std::string_view> kLidarPresets = {
    "velodyne_vlp16", "ouster_os1_64", "ouster_os1_128", "livox_mid40", "solid_state_raster"};
const std::vector<std::string_view> kImuPresets = {"consumer_mems", "tactical", "ideal"};

std::string Prefixed(const std::string& robot, const std::string& name) {
  if (robot.empty() || name == "world") return name;
  return robot + "/" + name;
}

// largest noise parameter of a sensor (standard deviations, densities, random walks).
constexpr double kMaxSensorNoise = 1e3;

double NonNegative(const ParamReader& r, const std::string& unit) {
  const double v = r.Double();
  if (v < 0) r.Fail("got " + FormatNumber(v) + "; expected a number >= 0 (" + unit + ")");
  return v;
}

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
  s.type = r.Child("type").Enum({"lidar", "imu", "mujoco", "ground_truth"});
  std::vector<std::string_view> keys = {"name", "type", "rate_hz", "latency_sec"};
  std::vector<std::string_view> noise_keys;
  if (s.type == "lidar") {
    keys.insert(keys.end(), {"body", "site", "pose", "preset", "columns", "min_range_m",
                             "max_range_m", "beam_divergence_mrad", "reference_reflectivity",
                             "intensity_range_normalized", "media", "noise"});
    noise_keys = {"range_stddev_m", "dropout_probability", "min_intensity", "receiver_noise"};
  } else if (s.type == "imu") {
    keys.insert(keys.end(), {"body", "site", "pose", "preset", "noise"});
    noise_keys = {"accel_noise_density", "accel_random_walk", "gyro_noise_density",
                  "gyro_random_walk"};
  } else if (s.type == "mujoco") {
    keys.insert(keys.end(), {"sensors", "noise"});
    noise_keys = {"stddev"};
  } else {
    keys.insert(keys.end(), {"bodies", "contacts"});
  }
  r.ExpectMap(keys);
  const std::string sensor = "sensor '" + s.name + "': ";
  if (r.Has("rate_hz")) {
    const ParamReader c = r.Child("rate_hz");
    s.rate_hz = c.Double();
    if (!(*s.rate_hz > 0))
      c.Fail(sensor + "got " + FormatNumber(*s.rate_hz) + "; expected a rate > 0 (Hz)");
  }
  if (const auto found = r.Find("latency_sec")) s.latency_sec = NonNegative(*found, "s");
  if (const auto found = r.Find("body")) s.body = Prefixed(robot, found->String());
  if (const auto found = r.Find("site")) s.site = Prefixed(robot, found->String());
  if (!s.body.empty() && !s.site.empty())
    r.Child("site").Fail(sensor + "both body and site are set; expected one of them");
  if (s.type == "imu" && s.body.empty() && s.site.empty())
    r.Fail(sensor + "an imu needs 'body' or 'site' to attach to");
  if ((s.type == "lidar") && s.body.empty() && s.site.empty()) s.body = "world";
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
    if (const auto found = p.Find("rpy_deg")) s.rpy_deg = found->Vector3();
  }
  if (s.type == "lidar") {
    s.preset = r.Child("preset").Enum(kLidarPresets);
  } else if (s.type == "imu") {
    s.preset = r.Has("preset") ? r.Child("preset").Enum(kImuPresets) : "consumer_mems";
  }
  if (r.Has("columns")) {
    const ParamReader c = r.Child("columns");
    const int v = c.Int();
    if (v < 1 || v > kMaxLidarBeamsPerScan)
      c.Fail(sensor + "got " + std::to_string(v) + "; expected an integer in [1, " +
             std::to_string(kMaxLidarBeamsPerScan) + "] (rings x columns is at most " +
             std::to_string(kMaxLidarBeamsPerScan) + " beams per scan)");
    s.params["columns"] = v;
  }
  for (const char* k : {"min_range_m", "max_range_m"})
    if (r.Has(k)) s.params[k] = NonNegative(r.Child(k), "m");
  if (r.Has("beam_divergence_mrad"))
    s.params["beam_divergence_mrad"] = NonNegative(r.Child("beam_divergence_mrad"), "mrad");
  if (r.Has("reference_reflectivity")) {
    const ParamReader c = r.Child("reference_reflectivity");
    const double v = c.Double();
    if (!(v > 0 && v <= 1)) c.Fail(sensor + "got " + FormatNumber(v) + "; expected (0, 1]");
    s.params["reference_reflectivity"] = v;
  }
  for (const char* k : {"intensity_range_normalized", "media", "contacts"})
    if (r.Has(k)) s.params[k] = r.Child(k).Bool() ? 1 : 0;
  if (r.Has("noise")) {
    const ParamReader n = r.Child("noise");
    n.ExpectMap(noise_keys);
    for (std::string_view k : noise_keys) {
      if (!n.Has(k)) continue;
      const ParamReader c = n.Child(k);
      const double v = c.Double();
      // 1e308 made every reading infinite
      if (!(v >= 0 && v <= kMaxSensorNoise))
        c.Fail(sensor + "got " + FormatNumber(v) +
               "; expected a noise value >= 0 and <= " + FormatNumber(kMaxSensorNoise));
      if (k == "dropout_probability" && v > 1)
        c.Fail(sensor + "got " + FormatNumber(v) + "; expected a probability in [0, 1]");
      s.params["noise." + std::string(k)] = v;
    }
  }
  for (const char* k : {"sensors", "bodies"}) {
    if (!r.Has(k)) continue;
    for (const ParamReader& e : r.Child(k).List()) s.names.push_back(Prefixed(robot, e.String()));
  }
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
