#pragma once
// what a sensor type implements (the contract of the sensor registry, sensor_types.h).
//
// a sensor type is a parameter struct P in sensors/types/<name>.{h,cc} and one entry in the
// SensorParams variant of sensor_types.h. P is plain data with defaults plus:
//
//   static constexpr SensorKind kKind;               // its enumerator (= its variant index)
//   static constexpr std::string_view kTypeName;     // world-file `type:`, "lidar"
//   static constexpr std::string_view kOutputFolder; // its folder in a run, "lidar"
//   static constexpr SensorAttach kAttach;           // body / site / pose keys and their rule
//   static constexpr double kDefaultRateHz;          // rate when rate_hz is not given
//   static constexpr bool kRateFromModel;            // true: the model's rate is used as is (no
//                                                    // cap at the physics rate)
//   static std::vector<std::string_view> Keys();     // its world-file keys beyond name, type,
//                                                    // rate_hz, latency_sec, body, site, pose
//   void Read(const SensorParamReader& r);           // parse and validate the keys present
//
// and the factory of its model (create), named after what it makes (LidarSensorParams::
// MakeConfig, ImuSensorParams::MakeNoise, ...), used by sinks/sensor_sink.cc.
//
// keys in Read are relative to the sensor entry ("columns", "noise.stddev"); the world reader
// (world/sensors_reader.cc) implements SensorParamReader over the YAML file and adds the
// entry's key path, line and the sensor's name to every error. nothing here depends on YAML.

#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace penumbra {

/// the sensor types, in the order of the SensorParams variant (sensor_types.h).
enum class SensorKind : int { kLidar = 0, kImu, kMujoco, kGroundTruth };

/// how a sensor type is mounted: which of the keys body, site and pose it has.
enum class SensorAttach {
  kNone,          ///< no mount (MuJoCo sensors, ground truth): no body, site or pose keys
  kDefaultWorld,  ///< body or site, the world frame when neither is given
  kRequired,      ///< body or site, one of them required
};

/// the keys of one sensor entry (or of a map inside it, e.g. `noise`), as the world reader
/// provides them. keys are relative to this node; every error names the file, line and key.
class SensorParamReader {
 public:
  virtual ~SensorParamReader() = default;

  /// whether key `k` is present.
  virtual bool Has(std::string_view k) const = 0;
  /// required values. @throws ConfigError when `k` is missing or has the wrong type.
  virtual double Double(std::string_view k) const = 0;
  virtual int Integer(std::string_view k) const = 0;
  virtual bool Boolean(std::string_view k) const = 0;
  /// one of `valid`. @throws ConfigError "unknown value '<v>'; expected one of: ..." otherwise.
  virtual std::string Enum(std::string_view k,
                           const std::vector<std::string_view>& valid) const = 0;
  /// a list of names of the composed model (bodies, MuJoCo sensors), each with the robot's
  /// "<robot>/" prefix when the entry is listed under a robot.
  /// @throws ConfigError when `k` is not a list of strings.
  virtual std::vector<std::string> Names(std::string_view k) const = 0;
  /// the map at `k`. @throws ConfigError when `k` is missing or not a map with only `keys`
  ///         ("unknown key '<k>'; expected one of: ...").
  virtual std::unique_ptr<SensorParamReader> Map(
      std::string_view k, const std::vector<std::string_view>& keys) const = 0;
  /// @throws ConfigError at key `k` ("" = this node) with `problem` (what is wrong and what
  ///         was expected).
  [[noreturn]] virtual void Fail(std::string_view k, const std::string& problem) const = 0;

  /// a number in [0, max] at `k` (`unit` names it in the message).
  /// @throws ConfigError "got <v>; expected a number in [0, <max>] (<unit>)".
  double NonNegative(std::string_view k, const std::string& unit, double max) const;
  /// a noise value at `k` of the `noise` map: in [0, kMaxSensorNoise].
  /// @throws ConfigError "got <v>; expected a noise value >= 0 and <= 1000".
  double Noise(std::string_view k) const;
};

/// `v` in the shortest form that reads back to the same double ("0.1", "1e+308"), for messages.
std::string SensorNumber(double v);

/// largest noise parameter of a sensor (standard deviations, densities, random walks):
/// 1e308 made every reading infinite.
inline constexpr double kMaxSensorNoise = 1e3;

}  // namespace penumbra
