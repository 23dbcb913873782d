#pragma once
// the ROS names of a world (docs/ros.md): topics and tf frames of every robot and sensor,
// derived from robot and sensor names unless the world file's `ros:` section
// (world/ros_config.h) sets them. used by the live bridge and by the rosbag export, so that a
// bag holds the same topics a live run publishes.
//
// defaults (N = ros.namespace, "" by default; R = a robot's namespace, its name by default):
//
//   /clock, /tf, /tf_static                       (never namespaced)
//   N/R/odom            nav_msgs/Odometry         ground truth of the robot's base body
//   N/R/joint_states    sensor_msgs/JointState    hinge and slide joints of the robot
//   N/R/cmd_vel         geometry_msgs/Twist       (subscribed) velocity command
//   N/R/joint_commands  sensor_msgs/JointState    (subscribed) joint position targets
//   N[/R]/<camera>/image_raw, camera_info         rgb8 image and its calibration
//   N[/R]/<camera>/depth/image_raw, camera_info   32FC1 z-depth in metres
//   N[/R]/<lidar>/points                          sensor_msgs/PointCloud2
//   N[/R]/<imu>/data                              sensor_msgs/Imu
//   N/mocap/<model>/<body>/pose                   (subscribed) geometry_msgs/PoseStamped
//
// a sensor mounted on a body of a robot gets the robot's namespace (/R/...); a sensor on the
// world or a static model none. characters a ROS name cannot hold ('-') become '_'.
//
// frames (REP-105): map (= the world frame W) -> odom -> base_link -> sensor frames. with one
// robot they are "odom" and "base_link"; with several, "<robot>/odom" and "<robot>/base_link".
// map -> odom is the identity (ground truth has no drift). a camera's frame is its OpenCV
// optical frame "<camera>/optical" (as camera_info.yaml names it); a LiDAR's or IMU's frame is
// "<sensor>" (its sensor frame S). a sensor on a robot hangs below the robot's base_link, any
// other below map.

#include <cstdint>
#include <string>
#include <vector>

#include "penumbra/control/model_info.h"
#include "penumbra/core/pose.h"
#include "penumbra/scene/scene_description.h"
#include "penumbra/world/ros_config.h"
#include "penumbra/world/world_config.h"

namespace penumbra {

/// what a sensor is.
enum class RosSensorKind { kCamera, kLidar, kImu };

/// a camera, LiDAR or IMU and where it is mounted.
struct RosSensorMount {
  std::string name;
  RosSensorKind kind = RosSensorKind::kCamera;
  /// body index (ModelInfo::body_names) the sensor is fixed to, 0 = the world; -1 = an MJCF
  /// camera, posed per frame by the snapshot (WorldSnapshot::X_W_mjcam[mjcf_camera]).
  int body = 0;
  int mjcf_camera = -1;             ///< MuJoCo camera id of an MJCF camera, else -1
  Pose X_BS = Pose::Identity();     ///< sensor frame in the body (cameras: the optical frame)
  CameraIntrinsics intrinsics;      ///< cameras
  double baseline_m = 0;            ///< cameras: > 0 for the right camera of a stereo pair
  bool rgb = false, depth = false;  ///< cameras: which images it makes
  /// IMUs: white-noise densities (Kalibr names), for the message covariances, and the rate
  double gyro_noise_density = 0, accel_noise_density = 0, rate_hz = 0;
};

/// a robot's names.
struct RosRobotGraph {
  std::string robot;  ///< model name
  int base_body = 0;  ///< body index of base_link
  std::string base_frame, odom_frame;
  std::string odom_topic, joint_states_topic, cmd_vel_topic, joint_commands_topic;
  /// hinge and slide joints of the robot (ModelInfo::joints indices), in model order; their
  /// JointState names are the composed joint names.
  std::vector<int> joints;
};

/// a sensor's names.
struct RosSensorGraph {
  RosSensorMount mount;
  int robot = -1;            ///< index into RosGraph::robots, -1 = none (world / static model)
  std::string frame_id;      ///< the sensor frame
  std::string parent_frame;  ///< its tf parent: the robot's base_frame or the map frame
  /// true when the sensor moves rigidly with its parent (a static transform on /tf_static)
  bool rigid_to_parent = false;
  std::string topic;  ///< base topic (N[/R]/<name>)
  // cameras
  std::string image_topic, info_topic, depth_image_topic, depth_info_topic;
  std::string points_topic;  ///< LiDARs
  std::string imu_topic;     ///< IMUs
};

/// every ROS name of a world.
struct RosGraph {
  std::string map_frame = "map";
  double state_rate_hz = 50;
  std::vector<RosRobotGraph> robots;
  std::vector<RosSensorGraph> sensors;
  /// mocap bodies (composed names) and their pose topics
  std::vector<std::string> mocap_bodies, mocap_topics;

  /// the sensor named `name`, or null.
  const RosSensorGraph* FindSensor(const std::string& name) const;
  /// every topic a bridge publishes, sorted (for messages and tests).
  std::vector<std::string> PublishedTopics() const;
};

/// a ROS name made of a world name: '-' and any other character a ROS name cannot hold become
/// '_'; a segment starting with a digit gets a leading '_'.
std::string RosNameOf(const std::string& world_name);

/// `ns` + "/" + `name` with single slashes ("" + "x" = "/x"; a `name` starting with '/' is
/// absolute and kept).
std::string JoinRosName(const std::string& ns, const std::string& name);

/// derives the names of `world`'s robots and of `sensors` on the composed model `model`, with
/// the overrides of `ros` (the world's `ros:` section: world/ros_config.h LoadRosConfig).
/// `mocap_bodies` are the model's mocap bodies (composed names).
/// @throws ConfigError (key "ros.robots.<r>.base_body" / "ros.sensors.<s>") for a base body
///         the robot does not have or an override naming an MJCF camera the model lacks; or
///         (key "ros") when two topics or two frames come out equal, naming both owners.
RosGraph BuildRosGraph(const WorldConfig& world, const RosConfig& ros, const ModelInfo& model,
                       const std::vector<RosSensorMount>& sensors,
                       const std::vector<std::string>& mocap_bodies = {});

/// the mounts of a composed world: `scene.cameras` (intrinsics, X_BO; MJCF cameras as body -1,
/// their robot found by their "<model>/" prefix) and the world file's LiDARs and IMUs (body or
/// site resolved in `model`).
/// @throws ConfigError (key of the sensor entry) for a body or site the model lacks.
std::vector<RosSensorMount> SensorMountsOf(const WorldConfig& world, const ModelInfo& model,
                                           const SceneDescription& scene);

/// the rigid body of body `b`: the first of `b` and its ancestors that a joint moves or that is
/// a mocap body (`mocap_bodies`, composed names); 0 for bodies welded to the world.
int RigidBodyOf(const ModelInfo& model, int b, const std::vector<std::string>& mocap_bodies);

}  // namespace penumbra
