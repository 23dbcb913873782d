// `penumbra bench ros2`'s harness (ros/ros2/ros2_bench.h) on a short run: it measures what it
// says (every stream sent and received, latencies ordered, every round trip answered) and
// refuses bad options by name. the numbers themselves are a benchmark, never checked here.
#include "penumbra/ros/ros2/ros2_bench.h"

#include <gtest/gtest.h>

#include <string>

#include "penumbra/core/error.h"
#include "penumbra/ros/ros2/ros2_types.h"

namespace penumbra {
namespace {

std::string ErrorOf(const Ros2BenchOptions& o) {
  try {
    RunRos2Bench(o);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(Ros2Bench, ShortRunMeasuresEveryStreamAndRoundTrip) {
  if (!Ros2Available()) GTEST_SKIP() << "this build has no ROS 2";
  Ros2BenchOptions o;
  o.width = 320;
  o.height = 240;
  o.seconds = 0.5;
  o.trips = 10;
  o.receive_buffer = 1 << 20;
  const Ros2BenchResult r = RunRos2Bench(o);
  EXPECT_GE(r.domain, 100);
  EXPECT_LE(r.domain, 232);
  ASSERT_EQ(r.topics.size(), 4u);
  EXPECT_EQ(r.topics[0].topic, "/bench/image_raw");
  EXPECT_EQ(r.topics[3].topic, "/tf");
  EXPECT_EQ(r.topics[3].qos, "RELIABLE KEEP_LAST 100");
  EXPECT_EQ(r.topics[0].bytes, 320 * 240 * 3);
  EXPECT_EQ(r.topics[1].bytes, 320 * 240 * 4);
  for (const Ros2TopicStats& t : r.topics) {
    SCOPED_TRACE(t.topic);
    // 0.5 s at 30, 30, 400 and 500 Hz (the first message at t = 0)
    EXPECT_GE(t.sent, 10);
    EXPECT_GT(t.received, 0);
    EXPECT_LE(t.received, t.sent);
    EXPECT_GT(t.median_ms, 0);
    EXPECT_LE(t.median_ms, t.p99_ms);
    EXPECT_LE(t.p99_ms, t.max_ms);
  }
  EXPECT_EQ(r.trips, 10);
  EXPECT_GT(r.trip_median_ms, 0);
  EXPECT_LE(r.trip_median_ms, r.trip_p99_ms);
}

TEST(Ros2Bench, DepthOffSendsNoDepthImage) {
  if (!Ros2Available()) GTEST_SKIP() << "this build has no ROS 2";
  Ros2BenchOptions o;
  o.width = 64;
  o.height = 48;
  o.seconds = 0.3;
  o.trips = 5;
  o.depth = false;
  const Ros2BenchResult r = RunRos2Bench(o);
  ASSERT_EQ(r.topics.size(), 4u);
  EXPECT_EQ(r.topics[1].sent, 0);
  EXPECT_EQ(r.topics[1].received, 0);
  EXPECT_GT(r.topics[0].received, 0);
}

TEST(Ros2Bench, BadOptionsAreRefusedByName) {
  if (!Ros2Available()) GTEST_SKIP() << "this build has no ROS 2";
  Ros2BenchOptions o;
  o.domain = 233;
  EXPECT_NE(ErrorOf(o).find("0..232"), std::string::npos) << ErrorOf(o);
  o = {};
  o.interface = "localhost";
  EXPECT_NE(ErrorOf(o).find("--ros-interface: 'localhost' is not a numeric"), std::string::npos)
      << ErrorOf(o);
  o = {};
  o.seconds = 0;
  EXPECT_NE(ErrorOf(o).find("--seconds"), std::string::npos) << ErrorOf(o);
  o = {};
  o.imu_hz = -1;
  EXPECT_NE(ErrorOf(o).find("IMU rate"), std::string::npos) << ErrorOf(o);
  o = {};
  o.width = 100000;
  EXPECT_NE(ErrorOf(o).find("image size"), std::string::npos) << ErrorOf(o);
  o = {};
  o.receive_buffer = -5;
  EXPECT_NE(ErrorOf(o).find("--receive-buffer"), std::string::npos) << ErrorOf(o);
}

}  // namespace
}  // namespace penumbra
