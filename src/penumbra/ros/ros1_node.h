#pragma once
// a ROS 1 node (roscpp) behind a ROS-free interface, for the live bridge (ros/ros_bridge.h):
// publishers of the plain messages of ros/ros_messages.h, subscriptions that hand plain
// messages to callbacks, std_srvs/Trigger services, /clock, and parameters. callbacks run on the
// node's own spinner threads (ros::AsyncSpinner) once Start() was called.
//
// C++17 header (implemented by the ROS-linked ros/ros1/ros1_node.cc). in a build without ROS 1
// the constructor throws Error.

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "penumbra/ros/ros_node.h"

namespace penumbra {

/// a ROS 1 node of this process (one per process: roscpp is a singleton).
class Ros1Node : public RosNode {
 public:
  /// settings of the node.
  struct Options {
    std::string name = "penumbra";  ///< node name
    /// the ROS master (e.g. "http://127.0.0.1:11311"); "" = $ROS_MASTER_URI
    std::string master_uri;
    /// sets the parameter /use_sim_time to true, so that nodes started afterwards take their
    /// time from /clock
    bool set_use_sim_time = true;
    int spinner_threads = 2;  ///< threads running subscription and service callbacks
  };

  /// initialises roscpp and checks that the master answers.
  /// @throws Error when no master answers at the URI (naming it), or when this build has no
  ///         ROS 1.
  explicit Ros1Node(const Options& options);
  /// stops the spinner and shuts the node down.
  ~Ros1Node() override;
  Ros1Node(const Ros1Node&) = delete;
  Ros1Node& operator=(const Ros1Node&) = delete;

  /// advertises `topic` (a resolved ROS name); returns the publisher's id. `queue_size`:
  /// messages kept per subscriber before the oldest is dropped (roscpp's policy: a slow
  /// subscriber never blocks the publisher).
  int Advertise(const std::string& topic, RosTopicType type, int queue_size) override;
  /// number of subscribers of publisher `id` (0: converting a message can be skipped).
  int Subscribers(int id) const override;

  /// publish on publisher `id` (its type must match; Error otherwise). thread-safe. image
  /// buffers of rvalue messages are moved into the ROS message.
  void Publish(int id, RosImage&& m) override;
  void Publish(int id, const RosCameraInfo& m) override;
  void Publish(int id, RosPointCloud2&& m) override;
  void Publish(int id, const RosImu& m) override;
  void Publish(int id, const RosJointState& m) override;
  void Publish(int id, const RosOdometry& m) override;
  /// one TFMessage of all `transforms` (kTf or kTfStatic).
  void Publish(int id, const std::vector<RosTransform>& transforms) override;
  /// a rosgraph_msgs/Clock (kClock).
  void PublishClock(int id, int64_t stamp_ns) override;

  /// subscriptions (geometry_msgs/Twist, sensor_msgs/JointState, geometry_msgs/PoseStamped).
  void SubscribeTwist(const std::string& topic,
                      std::function<void(const RosTwist&)> callback) override;
  void SubscribeJointState(const std::string& topic,
                           std::function<void(const RosJointState&)> callback) override;
  void SubscribePose(const std::string& topic,
                     std::function<void(const RosPoseStamped&)> callback) override;
  /// a std_srvs/Trigger service: the callback returns (success, message); it may block (it
  /// runs on a spinner thread).
  void AdvertiseTrigger(const std::string& service,
                        std::function<std::pair<bool, std::string>()> callback) override;

  /// an integer parameter (e.g. "/penumbra/steps_per_trigger"), or `fallback` when unset or
  /// not an integer.
  int64_t IntParam(const std::string& name, int64_t fallback) const override;
  /// sets a parameter.
  void SetParam(const std::string& name, int64_t value) override;

  /// starts the spinner threads (callbacks run from now on).
  void Start() override;
  /// the master URI the node talks to.
  std::string master_uri() const;
  /// "at <master URI>".
  std::string where() const override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace penumbra
