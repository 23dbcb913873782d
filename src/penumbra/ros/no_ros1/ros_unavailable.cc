// a build without ROS 1 (CMake PENUMBRA_WITH_ROS=OFF, or ROS 1 not found): every entry point
// of the ROS-linked files (ros/ros1/) refuses with an error that says how to get them.
#include "penumbra/core/error.h"
#include "penumbra/ros/rosbag_writer.h"

namespace penumbra {

namespace {
[[noreturn]] void NoRos(const std::string& what) {
  throw Error(what +
              " needs ROS 1, which this penumbra was built without: install the packages of "
              "scripts/install-deps.sh (ros-base-dev, libroscpp-dev, librosbag-dev, ...) and "
              "configure again with -DPENUMBRA_WITH_ROS=AUTO or ON");
}
}  // namespace

bool RosAvailable() { return false; }

struct RosbagWriter::Impl {};
RosbagWriter::RosbagWriter(const std::string& path) { NoRos("writing the bag " + path); }
RosbagWriter::~RosbagWriter() = default;
void RosbagWriter::Write(const std::string&, int64_t, const RosImage&) {}
void RosbagWriter::Write(const std::string&, int64_t, const RosCameraInfo&) {}
void RosbagWriter::Write(const std::string&, int64_t, const RosPointCloud2&) {}
void RosbagWriter::Write(const std::string&, int64_t, const RosImu&) {}
void RosbagWriter::Write(const std::string&, int64_t, const RosJointState&) {}
void RosbagWriter::Write(const std::string&, int64_t, const RosOdometry&) {}
void RosbagWriter::Write(const std::string&, int64_t, const RosTransform&) {}
void RosbagWriter::Close() {}

}  // namespace penumbra
