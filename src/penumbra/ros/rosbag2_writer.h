#pragma once
// a ROS 2 bag (rosbag2, MCAP storage) written from the plain messages of ros/ros_messages.h, as
// ROS 2 Jazzy's `ros2 bag record` lays it out:
//
//   DIR/metadata.yaml   rosbag2's metadata (version 9, storage_identifier mcap): every topic with
//                       its type, serialization_format cdr, offered_qos_profiles, RIHS01
//                       type_description_hash and message count; duration, starting time,
//                       message count, relative_file_paths and files
//   DIR/NAME_0.mcap     the MCAP file (ros/mcap_writer.h), profile "ros2": one Schema per type
//                       (encoding "ros2msg", the complete message definition of
//                       ros/ros2/ros2_types.h), one Channel per topic (message_encoding "cdr",
//                       metadata offered_qos_profiles and topic_type_hash), the messages as CDR
//                       (XCDR1 little endian, ros/ros2/ros2_types.h's SerializeCdr), zstd
//                       chunks, and a Metadata record "rosbag2" holding metadata.yaml's content
//
// readable by `ros2 bag info` / `ros2 bag play`, Foxglove and the rosbags and mcap libraries.
// the offered QoS of a topic is the one the live ROS 2 bridge offers (docs/ros.md): images,
// camera_info, points and IMU data BEST_EFFORT KEEP_LAST 5; odometry and joint states RELIABLE
// KEEP_LAST 10; /tf RELIABLE KEEP_LAST 100; /tf_static RELIABLE TRANSIENT_LOCAL KEEP_LAST 1; all
// VOLATILE but /tf_static, with infinite deadline, lifespan and lease, liveliness AUTOMATIC.
//
// needs the ROS 2 message types (Cyclone DDS, PENUMBRA_WITH_ROS2): in a build without them the
// constructor throws Error saying how to build them. no Cyclone header is included here.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "penumbra/ros/ros2_names.h"
#include "penumbra/ros/ros_messages.h"

namespace penumbra {

/// true if this build can write ROS 2 bags (it has the ROS 2 message types).
bool Rosbag2Available();
/// @throws Error saying how to build ROS 2 in a build without it (nothing otherwise).
void RequireRosbag2();

/// writes one ROS 2 bag into an existing folder. each Write stores the message on `topic` with
/// receive time `time_ns` (the MCAP log time and publish time; ros2 bag play publishes in this
/// order); a negative time is stored as 0.
class Rosbag2Writer {
 public:
  /// starts the bag in the existing, empty folder `dir`: creates `dir`/`name`_0.mcap. `name` is
  /// the bag's name (its folder's final name, when `dir` is a temporary one); messages name the
  /// bag `shown_dir` ("" = `dir`).
  /// @throws Error if this build has no ROS 2, `name` is empty or holds a '/', or the file
  ///         cannot be created (naming it and the system's reason).
  Rosbag2Writer(const std::filesystem::path& dir, const std::string& name,
                const std::string& shown_dir = "");
  /// finishes the bag (Close) unless it was closed or a write failed; logs errors, never throws.
  ~Rosbag2Writer();
  Rosbag2Writer(const Rosbag2Writer&) = delete;
  Rosbag2Writer& operator=(const Rosbag2Writer&) = delete;

  /// @throws Error naming the bag, the topic and the reason if the message cannot be converted
  ///         (a size the wire cannot hold), if `topic` had another type before, or if the write
  ///         fails (the system's reason, e.g. "No space left on device"), after which the bag is
  ///         abandoned and every further Write throws.
  void Write(const std::string& topic, int64_t time_ns, const RosImage& m);
  void Write(const std::string& topic, int64_t time_ns, const RosCameraInfo& m);
  void Write(const std::string& topic, int64_t time_ns, const RosPointCloud2& m);
  void Write(const std::string& topic, int64_t time_ns, const RosImu& m);
  void Write(const std::string& topic, int64_t time_ns, const RosJointState& m);
  void Write(const std::string& topic, int64_t time_ns, const RosOdometry& m);
  /// a tf2_msgs/msg/TFMessage of one transform (on /tf or /tf_static).
  void Write(const std::string& topic, int64_t time_ns, const RosTransform& m);

  /// messages written so far.
  int64_t messages() const { return messages_; }
  /// finishes the MCAP file and writes metadata.yaml (also done by the destructor).
  /// @throws Error naming the file and the system's reason (the bag is then abandoned).
  void Close();

  /// the offered_qos_profiles YAML (rosbag2's, Jazzy: a list of one profile with the policy
  /// names in lower case) of the QoS `q` (a topic's: Ros2WriterQos, ros/ros2_names.h), each line
  /// prefixed with `indent`. public for the tests.
  static std::string QosYaml(const Ros2QosProfile& q, const std::string& indent = "");

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  int64_t messages_ = 0;
};

}  // namespace penumbra
