#pragma once
// a ROS 2 node over Eclipse Cyclone DDS (its C API), speaking what rmw_cyclonedds_cpp (the
// Cyclone middleware of ROS 2 Humble, Jazzy, Kilted) puts on the wire, so that ROS 2 nodes see
// its topics and services as another node's:
//
//   topics    ROS name "/a/b" -> DDS topic "rt/a/b" (ros/ros2_names.h), DDS type names
//             "sensor_msgs::msg::dds_::Image_" ... (ros/ros2/ros2_types.h), XCDR1.
//   QoS       ROS 2's profiles: sensor data (Image, CameraInfo, PointCloud2, Imu) BEST_EFFORT
//             KEEP_LAST 5 VOLATILE; Odometry, JointState RELIABLE KEEP_LAST 10 VOLATILE; /tf
//             RELIABLE KEEP_LAST 100 VOLATILE (tf2_ros's DynamicBroadcasterQoS); /tf_static
//             RELIABLE TRANSIENT_LOCAL KEEP_LAST 1 (StaticBroadcasterQoS); /clock RELIABLE
//             KEEP_LAST 1 VOLATILE; subscriptions and services RELIABLE KEEP_LAST 10 VOLATILE.
//   USER_DATA "typehash=RIHS01_<hex>;" on every reader and writer (REP-2011, as rmw_cyclonedds
//             Iron and later: the type hash of the message, of Trigger_Request / _Response for
//             a service's two topics); "enclave=/;" on the participant.
//   services  std_srvs/srv/Trigger: requests on "rq/<name>Request", replies on
//             "rr/<name>Reply"; every sample starts with rmw_cyclonedds's request header
//             {uint64 guid; int64 seq} (cdds_request_header_t of its serdata.hpp), which the
//             reply echoes so that the calling client takes it as its answer. the request
//             reader and reply writer carry USER_DATA "serviceid=<id>;typehash=...;" (the same
//             id on both: rmw_cyclonedds's clients find a service's two halves by it).
//   domain    Options::domain_id (ros/ros2_names.h Ros2DomainId), created with dds_create_domain
//             from CycloneConfigXml(Options::interface_address): CYCLONEDDS_URI does not apply.
//   sockets   all on Options::interface_address: Cyclone binds its transmit socket there and its
//             unicast receive sockets (ports 7400 + 250 domain + 10 + 2 i and + 11 + 2 i) to the
//             wildcard address, which the node pins to the interface (ros/udp_bind_pin.h).
//             a multicast receive socket (only on a non-loopback interface) stays on the
//             wildcard: Linux delivers multicast only to sockets bound to it or to the group.
//   params    ROS 2 has no parameter server: IntParam / SetParam are values of this node.
//   graph     Start() publishes rmw_dds_common/msg/ParticipantEntitiesInfo on the DDS topic
//             "ros_discovery_info" (RELIABLE TRANSIENT_LOCAL KEEP_LAST 1; Jazzy's 16-byte GIDs:
//             the DDS GUIDs): the node /<name> with every reader and writer made before, so that
//             `ros2 node list` and `ros2 node info` show it.
//
// callbacks of subscriptions run on one thread of the node, each service on a thread of its own
// (a blocking call, e.g. a step of many physics steps, holds back neither cmd_vel nor pause), all
// started by Start().
// Cyclone checks every length of a received sample against its size before it allocates; the
// conversion (ros/ros2/ros2_types.h) bounds names and joint counts further, and a sample it
// refuses is logged and dropped.
//
// this header includes no DDS header; in a build without ROS 2 the constructor throws Error.

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "penumbra/ros/ros_node.h"

namespace penumbra {

/// a ROS 2 node of this process (one per process and domain).
class Ros2Node : public RosNode {
 public:
  /// settings of the node.
  struct Options {
    std::string name = "penumbra";  ///< node name (for the log and ros_discovery_info)
    int domain_id = 0;              ///< ROS 2 domain, [0, kRos2MaxDomainId]
    /// numeric address of the one network interface Cyclone uses (127.0.0.1: the loopback
    /// interface, as ROS_LOCALHOST_ONLY=1 / ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST)
    std::string interface_address = "127.0.0.1";
  };

  /// creates the DDS domain and participant.
  /// @throws ConfigError for a domain id or address out of range; Error when Cyclone cannot
  ///         create the domain (e.g. the address is not one of this machine's interfaces, or
  ///         a node of this process already uses the domain), naming Cyclone's reason; Error
  ///         when this build has no ROS 2.
  explicit Ros2Node(const Options& options);
  /// stops the callback threads and deletes the participant (and with it every reader and
  /// writer) and the domain.
  ~Ros2Node() override;
  Ros2Node(const Ros2Node&) = delete;
  Ros2Node& operator=(const Ros2Node&) = delete;

  /// a writer on "rt/<topic>" with the QoS of `type` (see the file header; `queue_size` is not
  /// used: the depth is the profile's).
  int Advertise(const std::string& topic, RosTopicType type, int queue_size) override;
  /// readers matched with the writer (its publication matched status): 0 until a ROS 2
  /// subscription has been discovered.
  int Subscribers(int id) const override;

  void Publish(int id, RosImage&& m) override;
  void Publish(int id, const RosCameraInfo& m) override;
  void Publish(int id, RosPointCloud2&& m) override;
  void Publish(int id, const RosImu& m) override;
  void Publish(int id, const RosJointState& m) override;
  void Publish(int id, const RosOdometry& m) override;
  void Publish(int id, const std::vector<RosTransform>& transforms) override;
  void PublishClock(int id, int64_t stamp_ns) override;

  void SubscribeTwist(const std::string& topic,
                      std::function<void(const RosTwist&)> callback) override;
  void SubscribeJointState(const std::string& topic,
                           std::function<void(const RosJointState&)> callback) override;
  void SubscribePose(const std::string& topic,
                     std::function<void(const RosPoseStamped&)> callback) override;
  /// a std_srvs/srv/Trigger service on "rq/<service>Request" / "rr/<service>Reply".
  void AdvertiseTrigger(const std::string& service,
                        std::function<std::pair<bool, std::string>()> callback) override;

  int64_t IntParam(const std::string& name, int64_t fallback) const override;
  void SetParam(const std::string& name, int64_t value) override;

  /// publishes ros_discovery_info (see the file header), then starts the callback threads.
  void Start() override;
  /// "in ROS 2 domain <id> on <address>".
  std::string where() const override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace penumbra
