#pragma once
// `penumbra run WORLD --ros [MASTER_URI]` / `--ros2`: the ROS 1 or ROS 2 bridge of a live run
// (docs/ros.md), a RunBridge (command/run_bridge.h) that publishes what the run produces on the
// topics of ros/ros_graph.h and turns ROS requests into the run's commands
// (command/command_dispatcher.h):
//
//   published   /clock (rosgraph_msgs/Clock) every physics step, at most once per ms of sim time;
//               camera images and CameraInfo as each frame completes; LiDAR PointCloud2 and
//               Imu as each sample is taken; Odometry, JointState and /tf at ros.state_rate_hz;
//               /tf_static once (latched). stamps are sim time.
//   subscribed  <robot>/cmd_vel (geometry_msgs/Twist: linear.x, linear.y, angular.z) -> the
//               `twist` command of the robot's controller; <robot>/joint_commands
//               (sensor_msgs/JointState: position, else velocity, else effort; by name or in
//               the controller's joint order) -> `joint_targets`; mocap/<body>/pose
//               (geometry_msgs/PoseStamped, world frame) -> `set_mocap`.
//   services    /penumbra/step, /penumbra/pause, /penumbra/resume, /penumbra/reset and
//               /penumbra/adversity/<preset> for each bundled adversity preset (none, minor,
//               major: the `set_adversity` command) (std_srvs/Trigger). step advances
//               steps_per_trigger physics steps (ROS 1: the parameter
//               /penumbra/steps_per_trigger, default 1; ROS 2: --ros-steps-per-trigger) and
//               replies once every message of those steps was published (lockstep:
//               `penumbra run --ros --lockstep` / `--ros2 --lockstep`).
//
// the same topics, types and services on both transports (ros/ros_node.h). a ROS 1 node sets
// /use_sim_time to true on the parameter server (nodes started afterwards use /clock); ROS 2 has
// no global parameters: ROS 2 nodes take /clock when started with use_sim_time:=true. a message is
// converted only when its topic has subscribers, so an idle bridge costs the run next to nothing;
// roscpp keeps a queue per subscriber and drops the oldest message of a slow one (queue sizes in
// the docs), a ROS 2 writer keeps the depth of its QoS profile (ros/ros2/ros2_node.h), so no
// subscriber can stall the simulation. a command the run refuses (a NaN twist, joints the
// controller does not drive, a wrong count) is logged as a warning naming the reason.

#include <cstdint>
#include <string>

#include "penumbra/command/run_bridge.h"

namespace penumbra {

/// which ROS.
enum class RosTransport {
  kRos1,  ///< roscpp and a ROS master (`--ros`)
  kRos2,  ///< DDS-RTPS through Cyclone DDS, as rmw_cyclonedds_cpp (`--ros2`)
};

/// settings of `--ros` / `--ros2`.
struct RosBridgeOptions {
  RosTransport transport = RosTransport::kRos1;
  std::string node_name = "penumbra";
  std::string master_uri;  ///< ROS 1: "" = $ROS_MASTER_URI
  int ros2_domain = 0;     ///< ROS 2 domain id, [0, 232] (ros/ros2_names.h Ros2DomainId)
  /// ROS 2: numeric address of the one network interface DDS uses (default loopback)
  std::string ros2_interface = "127.0.0.1";
  /// ROS 2: physics steps per /penumbra/step call (ROS 1 reads the parameter
  /// /penumbra/steps_per_trigger instead), >= 1
  int64_t steps_per_trigger = 1;
};

/// the factory of the ROS bridge for RunOptions::bridges.
/// the factory throws Error when no ROS master answers (ROS 1), when DDS cannot start on the
/// interface (ROS 2), or when this build lacks the transport, and ConfigError for a `ros:`
/// section that does not fit the composed model.
RunBridgeFactory MakeRosBridgeFactory(RosBridgeOptions options);

}  // namespace penumbra
