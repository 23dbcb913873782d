// a build without ROS 2 (CMake PENUMBRA_WITH_ROS2=OFF, or Cyclone DDS / idlc / the venv's rosbags
// not found): the ROS 2 node refuses with an error that says how to get it.
#include "penumbra/ros/ros2/ros2_node.h"

#include "penumbra/core/error.h"

namespace penumbra {

struct Ros2Node::Impl {};
Ros2Node::Ros2Node(const Options&) {
  throw Error(
      "the ROS 2 bridge (--ros2) needs ROS 2 support, which this penumbra was built without: "
      "install Cyclone DDS and the project venv (scripts/install-deps.sh) and configure again "
      "with -DPENUMBRA_WITH_ROS2=AUTO or ON");
}
Ros2Node::~Ros2Node() = default;
int Ros2Node::Advertise(const std::string&, RosTopicType, int) { return -1; }
int Ros2Node::Subscribers(int) const { return 0; }
void Ros2Node::Publish(int, RosImage&&) {}
void Ros2Node::Publish(int, const RosCameraInfo&) {}
void Ros2Node::Publish(int, RosPointCloud2&&) {}
void Ros2Node::Publish(int, const RosImu&) {}
void Ros2Node::Publish(int, const RosJointState&) {}
void Ros2Node::Publish(int, const RosOdometry&) {}
void Ros2Node::Publish(int, const std::vector<RosTransform>&) {}
void Ros2Node::PublishClock(int, int64_t) {}
void Ros2Node::SubscribeTwist(const std::string&, std::function<void(const RosTwist&)>) {}
void Ros2Node::SubscribeJointState(const std::string&, std::function<void(const RosJointState&)>) {}
void Ros2Node::SubscribePose(const std::string&, std::function<void(const RosPoseStamped&)>) {}
void Ros2Node::AdvertiseTrigger(const std::string&, std::function<std::pair<bool, std::string>()>) {
}
int64_t Ros2Node::IntParam(const std::string&, int64_t fallback) const { return fallback; }
void Ros2Node::SetParam(const std::string&, int64_t) {}
void Ros2Node::Start() {}
std::string Ros2Node::where() const { return ""; }

}  // namespace penumbra
