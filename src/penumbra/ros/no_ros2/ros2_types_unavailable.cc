// a build without ROS 2 (CMake PENUMBRA_WITH_ROS2=OFF, or Cyclone DDS, idlc or the venv's
// rosbags not found): the ROS 2 types refuse with an error that says how to get them.
#include "penumbra/core/error.h"
#include "penumbra/ros/ros2/ros2_types.h"

namespace penumbra {

namespace {
[[noreturn]] void NoRos2() {
  throw Error(
      "this penumbra was built without ROS 2 (Cyclone DDS): run scripts/install-deps.sh "
      "(cyclonedds-dev, cyclonedds-tools and the venv .venv with rosbags) and configure again "
      "with -DPENUMBRA_WITH_ROS2=AUTO or ON");
}
}  // namespace

bool Ros2Available() { return false; }
const Ros2TypeInfo& Ros2TypeOf(Ros2Type) { NoRos2(); }
void WithSample(const RosImage&, const std::function<void(const void*)>&) { NoRos2(); }
void WithSample(const RosCameraInfo&, const std::function<void(const void*)>&) { NoRos2(); }
void WithSample(const RosPointCloud2&, const std::function<void(const void*)>&) { NoRos2(); }
void WithSample(const RosImu&, const std::function<void(const void*)>&) { NoRos2(); }
void WithSample(const RosJointState&, const std::function<void(const void*)>&) { NoRos2(); }
void WithSample(const RosOdometry&, const std::function<void(const void*)>&) { NoRos2(); }
void WithSample(const std::vector<RosTransform>&, const std::function<void(const void*)>&) {
  NoRos2();
}
void WithSample(const RosTwist&, const std::function<void(const void*)>&) { NoRos2(); }
void WithSample(const RosPoseStamped&, const std::function<void(const void*)>&) { NoRos2(); }
void WithSample(const Ros2ParticipantEntities&, const std::function<void(const void*)>&) {
  NoRos2();
}
void WithClockSample(int64_t, const std::function<void(const void*)>&) { NoRos2(); }
void WithTriggerRequestSample(const Ros2RequestHeader&, const std::function<void(const void*)>&) {
  NoRos2();
}
void WithSample(const Ros2TriggerResponse&, const std::function<void(const void*)>&) { NoRos2(); }
std::vector<uint8_t> SerializeCdr(Ros2Type, const void*) { NoRos2(); }
void WithCdrSample(Ros2Type, std::span<const uint8_t>, const std::function<void(const void*)>&) {
  NoRos2();
}
RosTwist TwistFromSample(const void*) { NoRos2(); }
RosPoseStamped PoseStampedFromSample(const void*) { NoRos2(); }
RosJointState JointStateFromSample(const void*) { NoRos2(); }
Ros2RequestHeader TriggerRequestFromSample(const void*) { NoRos2(); }
Ros2TriggerResponse TriggerResponseFromSample(const void*) { NoRos2(); }
int64_t ClockFromSample(const void*) { NoRos2(); }
std::pair<int32_t, uint32_t> Ros2Stamp(int64_t) { NoRos2(); }

}  // namespace penumbra
