#pragma once
// the world file's `ros:` section (docs/ros.md): how the ROS 1 bridge (`penumbra run --ros`) and
// the rosbag export (`penumbra export --format rosbag`) name their topics and tf frames. every
// key is optional; the names derive from robot and sensor names (ros/ros_naming.h):
//
//   ros:
//     namespace: /sim             # prefix of every topic but /clock, /tf, /tf_static ("" = none)
//     map_frame: map              # REP-105 map frame (the world frame W)
//     state_rate_hz: 50           # odometry, joint_states and the dynamic tf per second of sim
//                                 # time, (0, 1000]
//     robots:                     # per robot, by its name
//       go1:
//         base_body: trunk        # body of base_link (model-local; default: the controller's
//                                 # base_body, else the model's first body)
//         base_frame: base_link   # default "base_link" (one robot) or "<robot>/base_link"
//         odom_frame: odom        # default "odom" (one robot) or "<robot>/odom"
//         namespace: go1          # topic namespace of the robot and its sensors (default: its
//         name)
//     sensors:                    # per camera, LiDAR or IMU, by its name
//       front: {topic: front_cam, frame_id: front_optical}
//
// the section is read and checked when the world file loads (LoadWorldFile / ParseWorld: keys,
// types, names, that the robots and sensors exist; errors name the line and key); the ROS
// module reads it again from the world file with LoadRosConfig when it needs the names.
//
// topic names follow ROS 1 graph-name rules (letters, digits, '_' and '/'; a segment starts with
// a letter; relative names are resolved under the namespaces above). frame ids are tf2 frame
// ids: no leading '/' (tf2 drops it), no spaces.

#include <string>
#include <vector>

namespace penumbra {

class ParamReader;
struct WorldConfig;

/// `ros.robots.<name>`.
struct RosRobotConfig {
  std::string robot;       ///< robot (model) name: the key
  std::string base_body;   ///< model-local body of base_link; "" = derived
  std::string base_frame;  ///< "" = derived
  std::string odom_frame;  ///< "" = derived
  std::string ns;          ///< `namespace:` of the robot's topics; "" = derived (its name)
};

/// `ros.sensors.<name>`.
struct RosSensorConfig {
  std::string sensor;    ///< camera or sensor name: the key
  std::string topic;     ///< base topic; "" = derived
  std::string frame_id;  ///< "" = derived
};

/// the `ros:` section.
struct RosConfig {
  std::string ns;                 ///< `namespace:`, "" = none
  std::string map_frame = "map";  ///< REP-105 map frame = the world frame
  double state_rate_hz = 50;      ///< odometry / joint states / dynamic tf rate, per sim second
  std::vector<RosRobotConfig> robots;
  std::vector<RosSensorConfig> sensors;

  /// checks rates and name syntax.
  /// @throws ConfigError (no file; key paths such as "ros.sensors.front.topic") naming what
  ///         was expected.
  void ValidateOrThrow() const;
};

/// reads the `ros:` section (types and keys; ranges in RosConfig::ValidateOrThrow).
/// @throws ConfigError naming file, line and key path.
RosConfig ReadRosConfig(const ParamReader& r);

/// checks that every robot of `ros.robots` is a robot of `world` and every sensor of
/// `ros.sensors` is a world-file camera, LiDAR or IMU (a name with '/', an MJCF camera, is
/// checked once the model is composed: ros/ros_graph.h).
/// @throws ConfigError (no file; key "ros.robots.<name>" / "ros.sensors.<name>") listing the
///         names the world has.
void ValidateRosReferences(const RosConfig& ros, const WorldConfig& world);

/// the `ros:` section of `world`'s world file (defaults when the world has no file or no
/// section), read and checked again (ReadRosConfig, ValidateOrThrow, ValidateRosReferences).
/// @throws ConfigError naming the world file, line and key.
RosConfig LoadRosConfig(const WorldConfig& world);

/// true if `name` is a valid ROS 1 graph name (absolute "/a/b", relative "a/b" or "~a"): segments
/// of letters, digits and '_' starting with a letter, separated by single '/'; no trailing '/'.
/// "" and "/" are not names.
bool IsValidRosName(const std::string& name);

/// true if `id` is usable as a tf2 frame id: non-empty, no leading '/', only letters, digits,
/// '_', '-', '.' and '/'.
bool IsValidFrameId(const std::string& id);

}  // namespace penumbra
