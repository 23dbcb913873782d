#include "penumbra/ros/ros2_names.h"

#include <arpa/inet.h>
#include <fmt/format.h>

#include <algorithm>
#include <charconv>

#include "penumbra/core/error.h"

namespace penumbra {

namespace {

// the name without its leading '/', checked
std::string Relative(const std::string& ros_name, const char* what) {
  if (ros_name.size() < 2 || ros_name.front() != '/')
    throw Error(fmt::format("the ROS 2 {} '{}' is not an absolute name (/a/b)", what, ros_name));
  return ros_name.substr(1);
}

int ParseDomain(const std::string& text, const std::string& key) {
  int v = -1;
  const auto r = std::from_chars(text.data(), text.data() + text.size(), v);
  if (text.empty() || r.ec != std::errc() || r.ptr != text.data() + text.size() || v < 0 ||
      v > kRos2MaxDomainId)
    throw ConfigError(
        "", 0, key,
        fmt::format("'{}' is not a ROS 2 domain id; expected an integer in [0, {}]",
                    text.size() > 40 ? text.substr(0, 40) + "..." : text, kRos2MaxDomainId));
  return v;
}

}  // namespace

std::string Ros2TopicName(const std::string& ros_name) {
  return "rt/" + Relative(ros_name, "topic");
}

std::string Ros2RequestTopic(const std::string& service) {
  return "rq/" + Relative(service, "service") + "Request";
}

std::string Ros2ReplyTopic(const std::string& service) {
  return "rr/" + Relative(service, "service") + "Reply";
}

int Ros2DomainId(const std::string& option, const char* env) {
  if (!option.empty()) return ParseDomain(option, "--ros-domain");
  if (env && *env) return ParseDomain(env, "ROS_DOMAIN_ID");
  return 0;
}

std::string CheckInterfaceAddress(const std::string& address) {
  unsigned char buf[16];
  if (address.size() > 64 || (inet_pton(AF_INET, address.c_str(), buf) != 1 &&
                              inet_pton(AF_INET6, address.c_str(), buf) != 1))
    throw ConfigError("", 0, "--ros-interface",
                      fmt::format("'{}' is not a numeric IPv4 or IPv6 address (e.g. 127.0.0.1, "
                                  "the default, or the address of one network interface)",
                                  address.size() > 64 ? address.substr(0, 64) + "..." : address));
  return address;
}

bool IsLoopbackAddress(const std::string& address) {
  unsigned char buf[16];
  if (inet_pton(AF_INET, address.c_str(), buf) == 1) return buf[0] == 127;
  if (inet_pton(AF_INET6, address.c_str(), buf) == 1) {
    static constexpr unsigned char kLoopback6[16] = {0, 0, 0, 0, 0, 0, 0, 0,
                                                     0, 0, 0, 0, 0, 0, 0, 1};
    return std::equal(buf, buf + 16, kLoopback6);
  }
  return false;
}

std::string CycloneConfigXml(const std::string& address) {
  const std::string a = CheckInterfaceAddress(address);
  std::string xml =
      "<CycloneDDS><Domain id=\"any\"><General><Interfaces><NetworkInterface address=\"" + a +
      "\"/></Interfaces>";
  if (!IsLoopbackAddress(a)) return xml + "</General></Domain></CycloneDDS>";
  // a loopback interface has no multicast: discovery by unicast to the participant ports of
  // this host, as rmw_cyclonedds_cpp's ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST. its MTU is 64 KiB:
  // samples go in 60 kB fragments, not Cyclone's default 1344 B (a 640x480 image is 16 UDP
  // datagrams instead of 686; `penumbra bench ros2`: median rgb latency 0.9 ms instead of 1.7)
  return xml +
         "<AllowMulticast>false</AllowMulticast><MaxMessageSize>65500B</MaxMessageSize>"
         "<FragmentSize>60000B</FragmentSize></General><Discovery><ParticipantIndex>auto</"
         "ParticipantIndex><MaxAutoParticipantIndex>32</MaxAutoParticipantIndex><Peers><Peer "
         "address=\"" +
         a + "\"/></Peers></Discovery></Domain></CycloneDDS>";
}

Ros2QosProfile Ros2WriterQos(RosTopicType t) {
  switch (t) {
    case RosTopicType::kImage:
    case RosTopicType::kCameraInfo:
    case RosTopicType::kPointCloud2:
    case RosTopicType::kImu:
      return kRos2SensorDataQos;
    case RosTopicType::kJointState:
    case RosTopicType::kOdometry:
      return kRos2DefaultQos;
    case RosTopicType::kTf:
      return kRos2TfQos;
    case RosTopicType::kTfStatic:
      return kRos2TfStaticQos;
    case RosTopicType::kClock:
      return kRos2ClockQos;
  }
  throw Error("unknown ROS topic type");
}

}  // namespace penumbra
