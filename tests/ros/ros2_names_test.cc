// the DDS side of the ROS 2 bridge that needs no peer (ros/ros2_names.h, ros/ros2/ros2_node.h):
// rmw_cyclonedds's name mapping, the domain id and its bounds, the interface address and the
// Cyclone DDS configuration, and a node's refusals.
#include "penumbra/ros/ros2_names.h"

#include <gtest/gtest.h>

#include <string>

#include "penumbra/core/error.h"
#include "penumbra/ros/ros2/ros2_node.h"
#include "penumbra/ros/ros2/ros2_types.h"

namespace penumbra {
namespace {

// the key of the ConfigError `f` throws ("" when it throws none)
template <typename F>
std::string ConfigErrorKey(F f) {
  try {
    f();
  } catch (const ConfigError& e) {
    return e.key();
  }
  return "";
}

TEST(Ros2Names, TopicsGetTheRtPrefix) {
  EXPECT_EQ(Ros2TopicName("/a/b"), "rt/a/b");
  EXPECT_EQ(Ros2TopicName("/clock"), "rt/clock");
  EXPECT_EQ(Ros2TopicName("/go1/front/image_raw"), "rt/go1/front/image_raw");
}

TEST(Ros2Names, ServicesGetRequestAndReplyTopics) {
  EXPECT_EQ(Ros2RequestTopic("/penumbra/step"), "rq/penumbra/stepRequest");
  EXPECT_EQ(Ros2ReplyTopic("/penumbra/step"), "rr/penumbra/stepReply");
  EXPECT_EQ(Ros2RequestTopic("/penumbra/adversity/minor"), "rq/penumbra/adversity/minorRequest");
  EXPECT_EQ(Ros2ReplyTopic("/penumbra/adversity/minor"), "rr/penumbra/adversity/minorReply");
}

TEST(Ros2Names, RelativeOrEmptyNamesAreRefused) {
  EXPECT_THROW(Ros2TopicName("a/b"), Error);
  EXPECT_THROW(Ros2TopicName("/"), Error);
  EXPECT_THROW(Ros2TopicName(""), Error);
  EXPECT_THROW(Ros2RequestTopic("step"), Error);
  EXPECT_THROW(Ros2ReplyTopic(""), Error);
}

TEST(Ros2Names, DomainFromOptionElseEnvironmentElseZero) {
  EXPECT_EQ(Ros2DomainId("", nullptr), 0);
  EXPECT_EQ(Ros2DomainId("", ""), 0);
  EXPECT_EQ(Ros2DomainId("", "5"), 5);
  EXPECT_EQ(Ros2DomainId("7", "5"), 7);
  EXPECT_EQ(Ros2DomainId("0", "5"), 0);
  EXPECT_EQ(Ros2DomainId(std::to_string(kRos2MaxDomainId), nullptr), 232);
}

TEST(Ros2Names, DomainOutOfRangeOrNotAnIntegerNamesItsSource) {
  for (const char* bad : {"233", "-1", "1e2", " 3", "3 ", "x", "99999999999999999999"}) {
    EXPECT_EQ(ConfigErrorKey([&] { Ros2DomainId(bad, nullptr); }), "--ros-domain") << bad;
    EXPECT_EQ(ConfigErrorKey([&] { Ros2DomainId("", bad); }), "ROS_DOMAIN_ID") << bad;
  }
  // a good option wins over a bad environment
  EXPECT_EQ(Ros2DomainId("3", "junk"), 3);
}

TEST(Ros2Names, InterfaceMustBeANumericAddress) {
  EXPECT_EQ(CheckInterfaceAddress("127.0.0.1"), "127.0.0.1");
  EXPECT_EQ(CheckInterfaceAddress("::1"), "::1");
  EXPECT_EQ(CheckInterfaceAddress("192.168.10.2"), "192.168.10.2");
  for (const char* bad : {"localhost", "", "127.0.0.1 ", "127.0.0.1\"/><x", "eth0", "1.2.3"})
    EXPECT_EQ(ConfigErrorKey([&] { CheckInterfaceAddress(bad); }), "--ros-interface") << bad;
  EXPECT_TRUE(IsLoopbackAddress("127.0.0.1"));
  EXPECT_TRUE(IsLoopbackAddress("127.1.2.3"));
  EXPECT_TRUE(IsLoopbackAddress("::1"));
  EXPECT_FALSE(IsLoopbackAddress("192.168.10.2"));
  EXPECT_FALSE(IsLoopbackAddress("::2"));
}

TEST(Ros2Names, CycloneConfigOfLoopbackIsRmwCycloneddsLocalhost) {
  EXPECT_EQ(CycloneConfigXml("127.0.0.1"),
            "<CycloneDDS><Domain id=\"any\"><General><Interfaces><NetworkInterface "
            "address=\"127.0.0.1\"/></Interfaces><AllowMulticast>false</AllowMulticast>"
            "<MaxMessageSize>65500B</MaxMessageSize><FragmentSize>60000B</FragmentSize>"
            "</General><Discovery><ParticipantIndex>auto</ParticipantIndex>"
            "<MaxAutoParticipantIndex>32</MaxAutoParticipantIndex><Peers><Peer "
            "address=\"127.0.0.1\"/></Peers></Discovery></Domain></CycloneDDS>");
}

TEST(Ros2Names, CycloneConfigOfAnotherInterfaceKeepsMulticastDiscovery) {
  EXPECT_EQ(CycloneConfigXml("192.168.10.2"),
            "<CycloneDDS><Domain id=\"any\"><General><Interfaces><NetworkInterface "
            "address=\"192.168.10.2\"/></Interfaces></General></Domain></CycloneDDS>");
  EXPECT_EQ(ConfigErrorKey([] { CycloneConfigXml("127.0.0.1\"/><Peer address=\"10.0.0.1"); }),
            "--ros-interface");
}

// a node is created only on an interface of this machine and only once per domain
TEST(Ros2Node, RefusesAForeignInterfaceAndASecondNodeInItsDomain) {
  if (!Ros2Available()) GTEST_SKIP() << "this build has no ROS 2";
  Ros2Node::Options o;
  o.domain_id = 229;
  o.interface_address = "127.0.0.1";
  Ros2Node node(o);
  EXPECT_EQ(node.where(), "in ROS 2 domain 229 on 127.0.0.1");
  try {
    Ros2Node again(o);
    ADD_FAILURE() << "a second node in domain 229 was created";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("already uses the domain"), std::string::npos) << e.what();
  }
  Ros2Node::Options foreign = o;
  foreign.domain_id = 230;
  foreign.interface_address = "192.0.2.1";  // TEST-NET-1: no interface of this machine
  EXPECT_THROW(Ros2Node bad(foreign), Error);
  Ros2Node::Options out_of_range = o;
  out_of_range.domain_id = 233;
  EXPECT_EQ(ConfigErrorKey([&] { Ros2Node n(out_of_range); }), "--ros-domain");
}

// a writer nobody reads has no subscribers (the bridge then skips the conversion), a relative
// topic is refused, and a publisher id of another type is an error
TEST(Ros2Node, AnIdleWriterHasNoSubscribers) {
  if (!Ros2Available()) GTEST_SKIP() << "this build has no ROS 2";
  Ros2Node::Options o;
  o.domain_id = 228;
  Ros2Node node(o);
  const int clock = node.Advertise("/clock", RosTopicType::kClock, 1);
  EXPECT_EQ(node.Subscribers(clock), 0);
  EXPECT_EQ(node.Subscribers(99), 0);
  EXPECT_THROW(node.Advertise("clock", RosTopicType::kClock, 1), Error);
  EXPECT_THROW(node.Publish(clock, RosImu{}), Error);
  node.PublishClock(clock, 1'500'000'000);
  node.SetParam("/penumbra/steps_per_trigger", 4);
  EXPECT_EQ(node.IntParam("/penumbra/steps_per_trigger", 1), 4);
  EXPECT_EQ(node.IntParam("/unset", 9), 9);
}

}  // namespace
}  // namespace penumbra
