#pragma once
// a ROS 1 bag file (format 2.0, http://wiki.ros.org/Bags/Format/2.0) written with the rosbag C++
// API (rosbag_storage, Debian's librosbag-dev), from the plain messages of ros/ros_messages.h.
// readable by `rosbag info`, `rosbag play` and every rosbag reader.
//
// C++17 header (included by the ROS-linked file ros/ros1/rosbag_writer.cc). in a build without
// ROS 1 (CMake PENUMBRA_WITH_ROS=OFF, or ROS not found) the constructor throws Error.
//
// a failed write (a full disk) throws Error with the system's reason and abandons the bag: the
// rosbag library's own close, which its destructor calls and which would throw again (and so
// abort the process: no exception may leave a destructor), then writes to /dev/null instead of
// the file. an abandoned bag is incomplete; the caller removes it.

#include <cstdint>
#include <memory>
#include <string>

#include "penumbra/ros/ros_messages.h"

namespace penumbra {

/// true if this build has the ROS 1 bridge and rosbag writer.
bool RosAvailable();

/// writes one bag. each Write stores the message on `topic` with receive time `time_ns`
/// (the bag's record time: when a subscriber would have had it; rosbag play publishes in this
/// order). a time below ROS's smallest valid time (1 ns) is stored as 1 ns.
class RosbagWriter {
 public:
  /// creates `path` (replacing a file of that name), uncompressed. messages name the bag
  /// `shown_path` ("" = `path`; e.g. the final name of a bag written under a temporary one).
  /// @throws Error naming the path if it cannot be created, or if this build has no ROS 1.
  explicit RosbagWriter(const std::string& path, const std::string& shown_path = "");
  ~RosbagWriter();
  RosbagWriter(const RosbagWriter&) = delete;
  RosbagWriter& operator=(const RosbagWriter&) = delete;

  /// @throws Error naming the bag, the topic and the system's reason (e.g. "No space left on
  ///         device") if the write fails, after which the bag is abandoned (see above) and
  ///         every further Write throws too.
  void Write(const std::string& topic, int64_t time_ns, const RosImage& m);
  void Write(const std::string& topic, int64_t time_ns, const RosCameraInfo& m);
  void Write(const std::string& topic, int64_t time_ns, const RosPointCloud2& m);
  void Write(const std::string& topic, int64_t time_ns, const RosImu& m);
  void Write(const std::string& topic, int64_t time_ns, const RosJointState& m);
  void Write(const std::string& topic, int64_t time_ns, const RosOdometry& m);
  /// a tf2_msgs/TFMessage of one transform (on /tf or /tf_static).
  void Write(const std::string& topic, int64_t time_ns, const RosTransform& m);

  /// messages written so far.
  int64_t messages() const { return messages_; }
  /// writes the index and closes the file (also done by the destructor, which logs errors and
  /// never throws).
  /// @throws Error if the file cannot be finished (the bag is then abandoned).
  void Close();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  int64_t messages_ = 0;
};

}  // namespace penumbra
