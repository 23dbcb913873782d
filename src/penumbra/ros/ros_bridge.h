#pragma once
// `penumbra run WORLD --ros [MASTER_URI]`: the ROS 1 bridge of a live run (docs/ros.md), a
// RunBridge (command/run_bridge.h) that publishes what the run produces on the topics of
// ros/ros_graph.h and turns ROS requests into the run's commands (command/command_dispatcher.h):
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
//   services    /penumbra/step, /penumbra/pause, /penumbra/resume, /penumbra/reset
//               (std_srvs/Trigger). step advances the parameter /penumbra/steps_per_trigger
//               physics steps (default 1) and replies once every message of those steps was
//               published (lockstep: `penumbra run --ros --lockstep`).
//
// the node sets /use_sim_time to true on the parameter server (nodes started afterwards use
// /clock). a message is converted only when its topic has subscribers, so an idle bridge costs
// the run next to nothing; roscpp keeps a queue per subscriber and drops the oldest message of a
// slow one (queue sizes in the docs), so no subscriber can stall the simulation.

#include <string>

#include "penumbra/command/run_bridge.h"

namespace penumbra {

/// settings of `--ros`.
struct RosBridgeOptions {
  std::string master_uri;  ///< "" = $ROS_MASTER_URI
  std::string node_name = "penumbra";
};

/// the factory of the ROS bridge for RunOptions::bridges.
/// the factory throws Error when no ROS master answers or this build has no ROS 1, and
/// ConfigError for a `ros:` section that does not fit the composed model.
RunBridgeFactory MakeRosBridgeFactory(RosBridgeOptions options);

}  // namespace penumbra
