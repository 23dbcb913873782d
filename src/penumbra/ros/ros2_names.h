#pragma once
// the names and settings of the ROS 2 bridge's DDS side that need no DDS library
// (ros/ros2/ros2_node.h uses them; tests check them in-process): how rmw_cyclonedds_cpp maps ROS 2
// names to DDS topic names, the ROS 2 domain id, the QoS of each topic (also what the rosbag2
// export records as offered_qos_profiles, and what `bench ros2` measures), and the Cyclone DDS
// configuration that keeps the node on one network interface.
//
// name mapping (rmw_cyclonedds_cpp, the ROS 2 design article "Topic and Service name mapping to
// DDS"): topic "/a/b" -> DDS topic "rt/a/b"; service "/a/b" -> request topic "rq/a/bRequest" and
// reply topic "rr/a/bReply".

#include <cstdint>
#include <string>

#include "penumbra/ros/ros_node.h"

namespace penumbra {

/// the largest ROS 2 domain id: DDS-RTPS maps a domain to UDP ports 7400 + 250 * id + ...,
/// which stay below 65536 up to 232 (ROS 2's "The ROS_DOMAIN_ID" article).
inline constexpr int kRos2MaxDomainId = 232;

/// the DDS topic of the ROS 2 topic `ros_name` ("/a/b" -> "rt/a/b").
/// @throws Error when `ros_name` is not absolute (does not start with '/') or is "/".
std::string Ros2TopicName(const std::string& ros_name);
/// the DDS topic of the requests of service `service` ("/a/b" -> "rq/a/bRequest").
/// @throws Error as Ros2TopicName.
std::string Ros2RequestTopic(const std::string& service);
/// the DDS topic of the replies of service `service` ("/a/b" -> "rr/a/bReply").
/// @throws Error as Ros2TopicName.
std::string Ros2ReplyTopic(const std::string& service);

/// the ROS 2 domain id: `option` (the text of --ros-domain) when not empty, else `env` (the
/// value of $ROS_DOMAIN_ID; null or empty = unset), else 0.
/// @throws ConfigError (key "--ros-domain" or "ROS_DOMAIN_ID") for anything but an integer in
///         [0, kRos2MaxDomainId].
int Ros2DomainId(const std::string& option, const char* env);

/// `address` when it is a numeric IPv4 or IPv6 address of this machine's kind (inet_pton),
/// else throws ConfigError (key "--ros-interface") naming what is expected. no name is
/// resolved.
std::string CheckInterfaceAddress(const std::string& address);

/// whether `address` (numeric) is a loopback address (127.0.0.0/8 or ::1).
bool IsLoopbackAddress(const std::string& address);

/// the Cyclone DDS configuration (XML, for dds_create_domain) of a node on the network
/// interface with the numeric address `address` (checked by CheckInterfaceAddress):
///   <CycloneDDS><Domain id="any"><General><Interfaces><NetworkInterface address="ADDR"/>
///   </Interfaces>...</General>...</Domain></CycloneDDS>
/// (the interface as rmw_cyclonedds_cpp pins it for ROS_LOCALHOST_ONLY=1); for a loopback
/// address, which has no multicast, also what rmw_cyclonedds_cpp (Jazzy) adds for
/// ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST: <AllowMulticast>false</AllowMulticast> in General and
/// <Discovery><ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>32
/// </MaxAutoParticipantIndex><Peers><Peer address="ADDR"/></Peers></Discovery>, and, as
/// loopback's MTU is 64 KiB, <MaxMessageSize>65500B</MaxMessageSize><FragmentSize>60000B
/// </FragmentSize> (fewer, larger UDP datagrams for images; any DDS reassembles them). Cyclone then
/// sends from and advertises that address only; its receive sockets it binds to the wildcard
/// address, which Ros2Node pins to ADDR (ros/udp_bind_pin.h).
/// @throws ConfigError as CheckInterfaceAddress.
std::string CycloneConfigXml(const std::string& address);

/// the QoS Penumbra sets on a ROS 2 endpoint: history KEEP_LAST `depth`, reliability and
/// durability; every other policy is the DDS default, as in ROS 2's profiles.
struct Ros2QosProfile {
  bool reliable = true;
  bool transient_local = false;
  int32_t depth = 10;
};

/// ROS 2's profiles (rmw/qos_profiles.h, tf2_ros/qos.hpp, rclcpp's ClockQoS).
inline constexpr Ros2QosProfile kRos2SensorDataQos{false, false, 5};  ///< sensor data
inline constexpr Ros2QosProfile kRos2DefaultQos{true, false, 10};     ///< default; services
inline constexpr Ros2QosProfile kRos2TfQos{true, false, 100};         ///< DynamicBroadcasterQoS
inline constexpr Ros2QosProfile kRos2TfStaticQos{true, true, 1};      ///< StaticBroadcasterQoS
/// /clock: reliable depth 1, which rclcpp's best-effort ClockQoS readers match too
inline constexpr Ros2QosProfile kRos2ClockQos{true, false, 1};

/// the writer QoS of the bridge's topics of type `t` (docs/ros.md's topic table): sensor data
/// for images, camera info, point clouds and IMU samples; default for odometry and joint states.
Ros2QosProfile Ros2WriterQos(RosTopicType t);

}  // namespace penumbra
