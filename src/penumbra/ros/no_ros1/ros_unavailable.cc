// a build without ROS 1 (CMake PENUMBRA_WITH_ROS=OFF, or ROS 1 not found): every entry point
// of the ROS-linked files (ros/ros1/) refuses with an error that says how to get them.
#include "penumbra/core/error.h"
#include "penumbra/ros/ros1_node.h"
#include "penumbra/ros/ros_bench.h"
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
RosbagWriter::RosbagWriter(const std::string& path, const std::string& shown_path) {
  NoRos("writing the bag " + (shown_path.empty() ? path : shown_path));
}
RosbagWriter::~RosbagWriter() = default;
void RosbagWriter::Write(const std::string&, int64_t, const RosImage&) {}
void RosbagWriter::Write(const std::string&, int64_t, const RosCameraInfo&) {}
void RosbagWriter::Write(const std::string&, int64_t, const RosPointCloud2&) {}
void RosbagWriter::Write(const std::string&, int64_t, const RosImu&) {}
void RosbagWriter::Write(const std::string&, int64_t, const RosJointState&) {}
void RosbagWriter::Write(const std::string&, int64_t, const RosOdometry&) {}
void RosbagWriter::Write(const std::string&, int64_t, const RosTransform&) {}
void RosbagWriter::Close() {}

RosBenchResult RunRosBench(const RosBenchOptions&) { NoRos("penumbra bench ros"); }

struct Ros1Node::Impl {};
Ros1Node::Ros1Node(const Options&) { NoRos("the ROS bridge (--ros)"); }
Ros1Node::~Ros1Node() = default;
int Ros1Node::Advertise(const std::string&, RosTopicType, int) { return -1; }
int Ros1Node::Subscribers(int) const { return 0; }
void Ros1Node::Publish(int, RosImage&&) {}
void Ros1Node::Publish(int, const RosCameraInfo&) {}
void Ros1Node::Publish(int, RosPointCloud2&&) {}
void Ros1Node::Publish(int, const RosImu&) {}
void Ros1Node::Publish(int, const RosJointState&) {}
void Ros1Node::Publish(int, const RosOdometry&) {}
void Ros1Node::Publish(int, const std::vector<RosTransform>&) {}
void Ros1Node::PublishClock(int, int64_t) {}
void Ros1Node::SubscribeTwist(const std::string&, std::function<void(const RosTwist&)>) {}
void Ros1Node::SubscribeJointState(const std::string&, std::function<void(const RosJointState&)>) {}
void Ros1Node::SubscribePose(const std::string&, std::function<void(const RosPoseStamped&)>) {}
void Ros1Node::AdvertiseTrigger(const std::string&, std::function<std::pair<bool, std::string>()>) {
}
int64_t Ros1Node::IntParam(const std::string&, int64_t fallback) const { return fallback; }
void Ros1Node::SetParam(const std::string&, int64_t) {}
void Ros1Node::Start() {}
std::string Ros1Node::master_uri() const { return ""; }
std::string Ros1Node::where() const { return ""; }

}  // namespace penumbra
