#pragma once
// a ROS node of this process behind a ROS-free interface, for the live bridge
// (ros/ros_bridge.h): publishers, subscriptions, std_srvs Trigger services and integer
// parameters. two transports implement it: ROS 1 (roscpp, ros/ros1_node.h) and ROS 2 (Cyclone
// DDS as rmw_cyclonedds_cpp speaks it, ros/ros2/ros2_node.h), so the bridge is written once.
//
// this header is C++17 (the ROS 1 files include it; ros/ros_messages.h says why).

#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "penumbra/ros/ros_messages.h"

namespace penumbra {

/// what a publisher sends.
enum class RosTopicType {
  kImage,        ///< sensor_msgs/Image
  kCameraInfo,   ///< sensor_msgs/CameraInfo
  kPointCloud2,  ///< sensor_msgs/PointCloud2
  kImu,          ///< sensor_msgs/Imu
  kJointState,   ///< sensor_msgs/JointState
  kOdometry,     ///< nav_msgs/Odometry
  kTf,           ///< tf2_msgs/TFMessage on /tf
  kTfStatic,     ///< tf2_msgs/TFMessage, latched (/tf_static; ROS 2: transient local)
  kClock,        ///< rosgraph_msgs/Clock
};

/// a ROS node: the transport-independent part of the live bridge's node.
/// Publish and Subscribers are thread-safe; the set-up calls (Advertise, Subscribe*,
/// AdvertiseTrigger, SetParam) are made before Start.
class RosNode {
 public:
  virtual ~RosNode() = default;

  /// advertises `topic` (a resolved ROS name, e.g. "/go1/odom"); returns the publisher's id.
  /// `queue_size`: messages kept per subscriber before the oldest is dropped (ROS 1); a
  /// ROS 2 node takes the depth of the type's QoS profile instead (ros/ros2/ros2_node.h).
  /// @throws Error when the transport cannot create the publisher.
  virtual int Advertise(const std::string& topic, RosTopicType type, int queue_size) = 0;
  /// number of subscribers of publisher `id` (0: converting a message can be skipped); 0 for
  /// an unknown id.
  virtual int Subscribers(int id) const = 0;

  /// publish on publisher `id` (its type must match; Error otherwise). image buffers of
  /// rvalue messages may be moved from.
  virtual void Publish(int id, RosImage&& m) = 0;
  virtual void Publish(int id, const RosCameraInfo& m) = 0;
  virtual void Publish(int id, RosPointCloud2&& m) = 0;
  virtual void Publish(int id, const RosImu& m) = 0;
  virtual void Publish(int id, const RosJointState& m) = 0;
  virtual void Publish(int id, const RosOdometry& m) = 0;
  /// one TFMessage of all `transforms` (kTf or kTfStatic).
  virtual void Publish(int id, const std::vector<RosTransform>& transforms) = 0;
  /// a rosgraph_msgs/Clock (kClock) at `stamp_ns` nanoseconds of sim time.
  virtual void PublishClock(int id, int64_t stamp_ns) = 0;

  /// subscriptions (geometry_msgs/Twist, sensor_msgs/JointState, geometry_msgs/PoseStamped)
  /// on a resolved ROS name; callbacks run on the node's threads once Start was called.
  virtual void SubscribeTwist(const std::string& topic,
                              std::function<void(const RosTwist&)> callback) = 0;
  virtual void SubscribeJointState(const std::string& topic,
                                   std::function<void(const RosJointState&)> callback) = 0;
  virtual void SubscribePose(const std::string& topic,
                             std::function<void(const RosPoseStamped&)> callback) = 0;
  /// a std_srvs Trigger service: the callback returns (success, message); it may block (it
  /// runs on a thread of the node, never on the simulation's).
  virtual void AdvertiseTrigger(const std::string& service,
                                std::function<std::pair<bool, std::string>()> callback) = 0;

  /// an integer parameter (e.g. "/penumbra/steps_per_trigger"), or `fallback` when unset or
  /// not an integer (ROS 1: the parameter server; ROS 2: a value of this node).
  virtual int64_t IntParam(const std::string& name, int64_t fallback) const = 0;
  /// sets a parameter.
  virtual void SetParam(const std::string& name, int64_t value) = 0;

  /// starts the threads that run subscription and service callbacks.
  virtual void Start() = 0;
  /// where the node is, for the log (e.g. "at http://127.0.0.1:11311" or "in ROS 2 domain
  /// 0 on 127.0.0.1").
  virtual std::string where() const = 0;
};

}  // namespace penumbra
