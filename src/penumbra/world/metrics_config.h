#pragma once
// the world file's `metrics:` section (docs/metrics.md): named time series recorded to CSV at a
// rate while a world runs, and their end-of-run summaries in run.json (the URLab paper's
// MetricManager). this header is its in-memory form and reader; metrics/metrics_sink.h records
// them. schema:
//
//   metrics:
//     rate_hz: 50                  # default rows per second of sim time, (0, 10000]
//     series:
//       - name: trunk              # unique; the file DIR/metrics/<name>.csv
//         type: body_pose          # see MetricKind
//         bodies: [go1/trunk]      # body_pose, body_twist: composed body names or globs
//         rate_hz: 100             # optional, overrides metrics.rate_hz
//       - {name: legs, type: joint_position, joints: ["go1/FR_*"]}   # joint_velocity,
//                                                                    # joint_torque alike
//       - {name: goal, type: distance, body: go1/trunk, to_point: [2, 0, 0.3]}  # or to_body
//       - {name: imu, type: sensor, sensors: [go1/imu_gyro]}         # MJCF sensors
//       - {name: track, type: tracking_error, robot: go1}            # the robot's controller
//       - name: bumps
//         type: contacts
//         min_force_N: 5           # a collision: normal force >= this, N (>= 0, default 1)
//         debounce_sec: 0.2        # episodes closer than this merge (>= 0, default 0.1)
//         between: [{a: "rover/*", b: "*"}]                   # pairs counted (default: any)
//         exclude: [{a: "rover/*", b: "arena/floor"}]          # pairs never counted
//         self_contacts: false     # contacts within one model (default false: not counted)
//         pair: body               # body | geom: what a pair is (default body)
//         detect_hz: 0             # collision detection rate; 0 = every physics step (default)
//
// globs: '*' any run of characters, '?' one character; a body/joint/sensor pattern must match
// at least one name of the composed model (checked when the session composes, by
// metrics/metrics_sink.h). a contact-rule pattern matches a contact side when it matches the
// side's geom name or its body name.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace penumbra {

class ParamReader;

/// what a metric records (`type:`); units and columns in docs/metrics.md.
enum class MetricKind {
  kBodyPose,       ///< body_pose: X_WB position (m) and orientation (quaternion w x y z)
  kBodyTwist,      ///< body_twist: V_WB angular (rad/s) and linear (m/s) in world axes
  kJointPosition,  ///< joint_position: qpos of the joints (rad, m; ball/free quaternions)
  kJointVelocity,  ///< joint_velocity: qvel of the joints (rad/s, m/s)
  kJointTorque,    ///< joint_torque: MuJoCo qfrc_actuator at the joints' dofs (N m, N)
  kDistance,       ///< distance: from a body's origin to a goal body's origin or a point, m
  kSensor,         ///< sensor: MJCF sensors' values (sensordata) in their units
  kTrackingError,  ///< tracking_error: what the robot's controller reports (control/controller.h)
  kContacts,       ///< contacts: contact counts, forces and collision episodes
};

/// the world-file name of a kind ("body_pose", ...).
std::string_view MetricKindName(MetricKind kind);

/// an unordered pair of glob patterns over contact sides (geom or body names).
struct ContactPairRule {
  std::string a = "*";
  std::string b = "*";
};

/// one entry of `metrics.series`.
struct MetricConfig {
  std::string name;  ///< [A-Za-z0-9_-]+, unique; names the CSV file
  MetricKind kind = MetricKind::kBodyPose;
  std::optional<double> rate_hz;     ///< rows per second of sim time; nullopt = MetricsConfig's
  std::vector<std::string> bodies;   ///< body_pose, body_twist: name globs, >= 1
  std::vector<std::string> joints;   ///< joint_*: name globs, >= 1
  std::vector<std::string> sensors;  ///< sensor: MJCF sensor name globs, >= 1
  std::string body;                  ///< distance: from this body (origin)
  std::string to_body;               ///< distance: to this body's origin; or
  std::optional<Eigen::Vector3d> to_point_m;  ///< distance: to this point, world frame, m
  std::string robot;                          ///< tracking_error: the robot (its model name)
  // contacts
  double min_force_N = 1.0;              ///< >= 0: an episode needs a pair's normal force >= this
  double debounce_sec = 0.1;             ///< >= 0: a pair's episodes less than this apart merge
  std::vector<ContactPairRule> between;  ///< pairs counted; empty = every pair
  std::vector<ContactPairRule> exclude;  ///< pairs never counted (after `between`)
  /// count contacts between two bodies of the same model ("<model>/" prefix; geoms of the
  /// world body belong to none)
  bool self_contacts = false;
  bool geom_pairs = false;  ///< pair: geom (true) or body (false)
  double detect_hz = 0;     ///< >= 0; 0 = every physics step
};

/// the `metrics:` section.
struct MetricsConfig {
  double rate_hz = 50;  ///< default rows per second of sim time, (0, 10000]
  std::vector<MetricConfig> series;

  /// true when the world records any metric.
  bool enabled() const { return !series.empty(); }
  /// the rate of `m`: its own or the section's, Hz.
  double RateOf(const MetricConfig& m) const { return m.rate_hz.value_or(rate_hz); }

  /// checks ranges, names and required fields.
  /// @throws ConfigError("", 0, key path e.g. "metrics.series[2].rate_hz", problem): the
  ///         world reader adds the file and line.
  void ValidateOrThrow() const;
};

/// reads the value of the `metrics` key (a mapping with rate_hz and series) and validates it.
/// @throws ConfigError naming the file, line and key path: unknown keys (also keys that do not
///         apply to the entry's type), wrong types, unknown types, missing required keys,
///         out-of-range values, duplicate names.
MetricsConfig ReadMetrics(const ParamReader& r);

}  // namespace penumbra
