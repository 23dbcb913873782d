#pragma once
// ROS 2 message types over Cyclone DDS: the plain messages of ros/ros_messages.h as the C structs
// that Cyclone's idlc generates from ROS 2 Jazzy's definitions (scripts/ros2_idl.py, build
// folder generated/ros2/ros2_msgs.h), their DDS type names, REP-2011 type hashes and rosbag2
// message definitions, and their CDR.
//
// type names are rmw_cyclonedds's: sensor_msgs/msg/Image is the DDS type
// "sensor_msgs::msg::dds_::Image_", the C struct sensor_msgs_msg_dds__Image_ and its descriptor
// sensor_msgs_msg_dds__Image__desc. units SI, frames REP-103 / REP-105 as in ros_messages.h.
// stamps: builtin_interfaces/Time {int32 sec, uint32 nanosec} of stamp_ns, sec = floor(stamp_ns /
// 1e9) and 0 <= nanosec < 1e9 (a negative stamp has a negative sec).
//
// this header needs no Cyclone header: samples are passed as `const void*` pointing at the C
// struct of the type. in a build without ROS 2 (src/penumbra/ros/no_ros2/) every function but
// Ros2Available throws Error saying so.

#include <array>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "penumbra/ros/ros_messages.h"
#include "penumbra/ros/ros_node.h"

struct dds_topic_descriptor;
typedef struct dds_topic_descriptor dds_topic_descriptor_t;

namespace penumbra {

/// whether this build has ROS 2 (Cyclone DDS and the generated types).
bool Ros2Available();

/// the ROS 2 types Penumbra publishes, subscribes to or serves.
enum class Ros2Type {
  kImage,                    ///< sensor_msgs/msg/Image
  kCameraInfo,               ///< sensor_msgs/msg/CameraInfo
  kPointCloud2,              ///< sensor_msgs/msg/PointCloud2
  kImu,                      ///< sensor_msgs/msg/Imu
  kJointState,               ///< sensor_msgs/msg/JointState
  kOdometry,                 ///< nav_msgs/msg/Odometry
  kTfMessage,                ///< tf2_msgs/msg/TFMessage (/tf, /tf_static)
  kClock,                    ///< rosgraph_msgs/msg/Clock (/clock)
  kTwist,                    ///< geometry_msgs/msg/Twist (cmd_vel)
  kPoseStamped,              ///< geometry_msgs/msg/PoseStamped
  kTriggerRequest,           ///< std_srvs/srv/Trigger_Request, with the request header
  kTriggerResponse,          ///< std_srvs/srv/Trigger_Response, with the request header
  kParticipantEntitiesInfo,  ///< rmw_dds_common/msg/ParticipantEntitiesInfo (ros_discovery_info)
};
/// the number of Ros2Type values.
inline constexpr int kRos2TypeCount = 13;

/// what a Ros2Type is on the wire and in a bag.
struct Ros2TypeInfo {
  const char* ros_name;  ///< "sensor_msgs/msg/Image"
  const char* dds_name;  ///< "sensor_msgs::msg::dds_::Image_" (rmw_cyclonedds)
  /// "RIHS01_" + 64 hex digits: REP-2011's hash of the ROS type (a service's Request/Response
  /// without the request header), computed by scripts/ros2_idl.py; for the writer and reader
  /// USER_DATA "typehash=<hash>;" of rmw_cyclonedds (ROS 2 Iron and later).
  const char* type_hash;
  /// the complete message definition, MCAP schema encoding "ros2msg" in rosbag2's layout: the
  /// type's .msg fields, then per dependency (depth first, each once) a line of 80 '=', a line
  /// "MSG: pkg/Type" and its fields. field lines only: the .msg files' comments are not in it.
  const char* definition;
  const dds_topic_descriptor_t* descriptor;  ///< idlc's descriptor for dds_create_topic
};

/// the table entry of `type`. throws Error for a value outside the enum.
const Ros2TypeInfo& Ros2TypeOf(Ros2Type type);

/// the ROS 2 message type of the bridge's topics of type `t` (/tf and /tf_static: TFMessage).
constexpr Ros2Type Ros2TypeOfTopic(RosTopicType t) {
  switch (t) {
    case RosTopicType::kImage:
      return Ros2Type::kImage;
    case RosTopicType::kCameraInfo:
      return Ros2Type::kCameraInfo;
    case RosTopicType::kPointCloud2:
      return Ros2Type::kPointCloud2;
    case RosTopicType::kImu:
      return Ros2Type::kImu;
    case RosTopicType::kJointState:
      return Ros2Type::kJointState;
    case RosTopicType::kOdometry:
      return Ros2Type::kOdometry;
    case RosTopicType::kTf:
    case RosTopicType::kTfStatic:
      return Ros2Type::kTfMessage;
    case RosTopicType::kClock:
      return Ros2Type::kClock;
  }
  return Ros2Type::kClock;  // not reached: every enumerator is handled above
}

/// the most joints a received JointState may name, and the longest string (joint name, frame id,
/// Trigger message) read from a received sample, in bytes: larger ones are refused with an Error.
inline constexpr uint32_t kRos2MaxJoints = 1024;
inline constexpr uint32_t kRos2MaxNameBytes = 1024;

/// rmw_cyclonedds's request header, the first 16 bytes of a service request and of its reply:
/// the client's GUID (its request writer's, as 64 bits) and the request's sequence number. a
/// reply carries its request's header.
struct Ros2RequestHeader {
  uint64_t client_guid = 0;
  int64_t sequence_number = 0;
};

/// a std_srvs/srv/Trigger reply.
struct Ros2TriggerResponse {
  Ros2RequestHeader header;
  bool success = false;
  std::string message;
};

/// rmw_dds_common/msg/ParticipantEntitiesInfo: the nodes of a DDS participant and the GIDs of
/// their readers and writers (16 bytes each: the DDS GUID, zero padded), as ROS 2 publishes them
/// on ros_discovery_info for `ros2 node list`.
struct Ros2ParticipantEntities {
  using Gid = std::array<uint8_t, 16>;
  struct Node {
    std::string node_namespace;  ///< "/" (at most 256 bytes)
    std::string node_name;       ///< "penumbra" (at most 256 bytes)
    std::vector<Gid> readers, writers;
  };
  Gid gid{};  ///< the participant's
  std::vector<Node> nodes;
};

// the messages as the generated C structs: f gets a pointer to a sample of the type named on
// each function, whose strings and sequences borrow m's memory (valid while f runs). sizes that
// do not fit the wire's 32-bit lengths, and stamps outside int32 seconds, throw Error.

/// sensor_msgs/msg/Image.
void WithSample(const RosImage& m, const std::function<void(const void*)>& f);
/// sensor_msgs/msg/CameraInfo (d, k, r, p from D, K, R, P; binning 0, roi all zero).
void WithSample(const RosCameraInfo& m, const std::function<void(const void*)>& f);
/// sensor_msgs/msg/PointCloud2.
void WithSample(const RosPointCloud2& m, const std::function<void(const void*)>& f);
/// sensor_msgs/msg/Imu.
void WithSample(const RosImu& m, const std::function<void(const void*)>& f);
/// sensor_msgs/msg/JointState.
void WithSample(const RosJointState& m, const std::function<void(const void*)>& f);
/// nav_msgs/msg/Odometry.
void WithSample(const RosOdometry& m, const std::function<void(const void*)>& f);
/// tf2_msgs/msg/TFMessage of the transforms (each a geometry_msgs/TransformStamped).
void WithSample(const std::vector<RosTransform>& m, const std::function<void(const void*)>& f);
/// geometry_msgs/msg/Twist.
void WithSample(const RosTwist& m, const std::function<void(const void*)>& f);
/// geometry_msgs/msg/PoseStamped.
void WithSample(const RosPoseStamped& m, const std::function<void(const void*)>& f);
/// rmw_dds_common/msg/ParticipantEntitiesInfo. names over 256 bytes throw Error.
void WithSample(const Ros2ParticipantEntities& m, const std::function<void(const void*)>& f);
/// rosgraph_msgs/msg/Clock at stamp_ns (sim time, ns).
void WithClockSample(int64_t stamp_ns, const std::function<void(const void*)>& f);
/// std_srvs/srv/Trigger_Request with its request header.
void WithTriggerRequestSample(const Ros2RequestHeader& h,
                              const std::function<void(const void*)>& f);
/// std_srvs/srv/Trigger_Response with the header of the request it answers.
void WithSample(const Ros2TriggerResponse& m, const std::function<void(const void*)>& f);

/// the CDR of a sample of `type` (XCDR1, little endian) as rmw_cyclonedds puts it on the wire and
/// rosbag2 stores it: the encapsulation header {0x00, 0x01, 0x00, n}, the data, then n (0-3)
/// zero bytes of padding to a multiple of 4 (Cyclone DDS's serialized form). throws Error where
/// Cyclone refuses the sample (e.g. a bounded sequence over its bound).
std::vector<uint8_t> SerializeCdr(Ros2Type type, const void* sample);

/// reads the CDR of a sample of `type` (an encapsulation header for XCDR1, little or big endian,
/// then the data), checking every length against the buffer before anything is allocated, and
/// calls f with the sample as the generated C struct (freed after f). throws Error naming the
/// type when the bytes are not a valid sample.
void WithCdrSample(Ros2Type type, std::span<const uint8_t> cdr,
                   const std::function<void(const void*)>& f);

// samples received (the generated C structs) as plain messages. strings and sequences over the
// bounds above, a nanosec of 1e9 or more, and joint arrays whose non-empty lengths differ from
// a non-empty name's throw Error naming the field (with no names, the arrays are in the
// controller's joint order, as the ROS 1 bridge takes them).

/// geometry_msgs/msg/Twist. the values are not checked (the dispatcher refuses NaN commands).
RosTwist TwistFromSample(const void* sample);
/// geometry_msgs/msg/PoseStamped.
RosPoseStamped PoseStampedFromSample(const void* sample);
/// sensor_msgs/msg/JointState (position, velocity, effort may each be empty; name may be empty,
/// the values then being in the controller's joint order).
RosJointState JointStateFromSample(const void* sample);
/// the request header of a std_srvs/srv/Trigger_Request.
Ros2RequestHeader TriggerRequestFromSample(const void* sample);
/// a std_srvs/srv/Trigger_Response.
Ros2TriggerResponse TriggerResponseFromSample(const void* sample);
/// builtin_interfaces/Time of rosgraph_msgs/msg/Clock as ns.
int64_t ClockFromSample(const void* sample);

/// builtin_interfaces/Time of stamp_ns: {sec, nanosec}. throws Error outside int32 seconds.
std::pair<int32_t, uint32_t> Ros2Stamp(int64_t stamp_ns);

}  // namespace penumbra
