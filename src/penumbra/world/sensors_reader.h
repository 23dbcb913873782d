#pragma once
// the world file's `sensors:` list (top level, and under a robot entry) in memory, and its
// reader. schema (README "sensors"):
//
//   sensors:
//     - name: front_lidar          # unique over the world; names the output folder / file
//       type: lidar                # lidar | imu | mujoco | ground_truth
//       body: go1/trunk            # attach to a body ("world" allowed) ...
//       site: go1/imu              # ... or to a site (not both; imu: one of them required)
//       pose: {xyz: [0.2, 0, 0.1], rpy_deg: [0, 0, 0]}  # sensor frame in the body/site frame
//       rate_hz: 10                # > 0; default: the preset's (lidar), 200 (imu), 100 (others)
//       latency_sec: 0.0           # >= 0; delivery stamp = capture stamp + latency
//       preset: ouster_os1_64      # lidar: velodyne_vlp16 | ouster_os1_64 | ouster_os1_128 |
//                                  #        livox_mid40 | solid_state_raster
//                                  # imu:   consumer_mems | tactical | ideal
//       # lidar overrides: columns, min_range_m, max_range_m, beam_divergence_mrad,
//       #   reference_reflectivity, intensity_range_normalized (bool), media (bool)
//       noise:                     # every value >= 0
//         # lidar: range_stddev_m, dropout_probability (<= 1), min_intensity, receiver_noise
//         # imu:   accel_noise_density, accel_random_walk, gyro_noise_density, gyro_random_walk
//         # mujoco: stddev (Gaussian, added to every value)
//       sensors: [go1/touch_fl]    # mujoco: MJCF sensor names (default: all)
//       bodies: [go1/trunk]        # ground_truth: bodies to record (default: all named bodies)
//       contacts: true             # ground_truth: also write contacts.csv
//
// under a robot (robots[i].sensors) the same entries attach to that robot: body and site
// names and mujoco sensor names are given without the "<robot>/" prefix and get it here.
// body/site existence is checked after composition (sinks/sensor_sink), naming the entry.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "penumbra/core/pose.h"
#include "penumbra/sensors/sensor_types.h"

namespace penumbra {

class ParamReader;

/// one world-file sensor.
struct SensorConfig {
  std::string name;
  /// the type's parameters (sensors/sensor_types.h); the alternative held is the sensor's type.
  SensorParams params;
  std::string robot;  ///< robot it was listed under ("" = top-level list)
  std::string body;   ///< attach body, composed name ("world" = world frame); "" if site set
  std::string site;   ///< attach site, composed name; "" if body set
  Eigen::Vector3d xyz{0, 0, 0};      ///< sensor frame in the attach frame: translation, m
  Eigen::Vector3d rpy_deg{0, 0, 0};  ///< and roll, pitch, yaw (deg, REP-103)
  /// X_AS: pose of the sensor frame S in the attach frame A.
  Pose X_AS() const { return PoseFromXyzRpyDeg(xyz, rpy_deg); }
  std::optional<double> rate_hz;  ///< nullopt = the type's default
  double latency_sec = 0;
  std::string file;  ///< world file, for messages
  int line = 0;      ///< line of the entry
  std::string key;   ///< key path of the entry, e.g. "sensors[1]" or "robots[0].sensors[0]"

  /// the sensor's type.
  SensorKind kind() const { return KindOf(params); }
  /// the type's parameters; nullptr when the sensor is of another type.
  template <typename P>
  const P* get() const {
    return std::get_if<P>(&params);
  }
};

/// reads a `sensors:` list of world file `file`; entries under robot `robot` ("" = top level) get
/// its prefix.
/// @throws ConfigError (file, line, key path such as sensors[2].rate_hz, expected range)
///         for unknown keys or types, a missing name/type/preset, zero or negative rates,
///         negative latency or noise, unknown presets, body and site both or neither (imu).
std::vector<SensorConfig> ReadSensors(const ParamReader& list, const std::string& file,
                                      const std::string& robot);

/// checks that sensor names are unique over `sensors`.
/// @throws ConfigError naming the second entry with a repeated name.
void ValidateSensorNames(const std::vector<SensorConfig>& sensors);

}  // namespace penumbra
