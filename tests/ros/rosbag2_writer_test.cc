// the ROS 2 bag writer (ros/rosbag2_writer.h): layout, metadata.yaml, QoS, refusals. the bag's
// content is read back by the official mcap reader and rosbags in tests/ros/rosbag2_export_test.py.
#include "penumbra/ros/rosbag2_writer.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "common/temp_dir.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

#define EXPECT_HAS(text, part) EXPECT_NE((text).find(part), std::string::npos) << (text)

TEST(Rosbag2Writer, ABuildWithoutRos2SaysSo) {
  if (Rosbag2Available()) GTEST_SKIP() << "this build has ROS 2";
  testing::TempDir dir;
  try {
    Rosbag2Writer w(dir.path(), "bag");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_HAS(std::string(e.what()), "ROS 2");
  }
  EXPECT_THROW(RequireRosbag2(), Error);
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

TEST(Rosbag2Writer, WritesTheMcapFileAndMetadataYaml) {
  if (!Rosbag2Available()) GTEST_SKIP() << "this build has no ROS 2";
  testing::TempDir dir;
  {
    Rosbag2Writer w(dir.path(), "my_bag", "/shown/my_bag");
    RosImu imu;
    imu.header = {1500000000, "imu"};
    w.Write("/imu", 1502000000, imu);
    w.Write("/imu", 1504000000, imu);
    RosTransform tf;
    tf.header = {0, "map"};
    tf.child_frame_id = "odom";
    w.Write("/tf_static", -5, tf);  // a negative record time is stored as 0
    // a topic keeps its type: refused, and the bag goes on
    try {
      w.Write("/imu", 1, RosJointState{});
      FAIL() << "no error";
    } catch (const Error& e) {
      EXPECT_HAS(std::string(e.what()), "/imu");
      EXPECT_HAS(std::string(e.what()), "sensor_msgs/msg/Imu");
      EXPECT_HAS(std::string(e.what()), "/shown/my_bag");
    }
    w.Write("/imu", 1506000000, imu);
    EXPECT_EQ(w.messages(), 4);
    w.Close();
    EXPECT_THROW(w.Write("/imu", 1, imu), Error);  // closed
  }
  EXPECT_TRUE(fs::is_regular_file(dir.path() / "my_bag_0.mcap"));
  const std::string y = testing::ReadAll(dir.path() / "metadata.yaml");
  EXPECT_EQ(y.rfind("rosbag2_bagfile_information:\n  version: 9\n  storage_identifier: mcap\n", 0),
            0u)
      << y;
  EXPECT_HAS(y, "  message_count: 4\n");
  EXPECT_HAS(y, "  starting_time:\n    nanoseconds_since_epoch: 0\n");
  EXPECT_HAS(y, "  duration:\n    nanoseconds: 1506000000\n");
  EXPECT_HAS(y, "  relative_file_paths:\n    - \"my_bag_0.mcap\"\n");
  EXPECT_HAS(y, "        name: \"/imu\"\n        type: \"sensor_msgs/msg/Imu\"\n");
  EXPECT_HAS(y, "        type_description_hash: \"RIHS01_");
  EXPECT_HAS(y, "      message_count: 3\n");
  EXPECT_HAS(y, "      message_count: 1\n");
}

TEST(Rosbag2Writer, BadNamesAreRefused) {
  if (!Rosbag2Available()) GTEST_SKIP() << "this build has no ROS 2";
  testing::TempDir dir;
  for (const std::string name : {"", ".", "..", "a/b"})
    EXPECT_THROW(Rosbag2Writer(dir.path(), name), Error) << name;
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

TEST(Rosbag2Writer, QosIsTheLiveBridges) {
  const std::string image = Rosbag2Writer::QosYaml(Ros2WriterQos(RosTopicType::kImage));
  EXPECT_HAS(image, "- history: keep_last\n  depth: 5\n  reliability: best_effort\n");
  EXPECT_HAS(image, "  durability: volatile\n");
  EXPECT_HAS(image, "  deadline:\n    sec: 9223372036\n    nsec: 854775807\n");
  EXPECT_HAS(image, "  liveliness: automatic\n");
  EXPECT_HAS(image, "  avoid_ros_namespace_conventions: false\n");
  const std::string odom = Rosbag2Writer::QosYaml(Ros2WriterQos(RosTopicType::kOdometry));
  EXPECT_HAS(odom, "  depth: 10\n  reliability: reliable\n  durability: volatile\n");
  EXPECT_HAS(Rosbag2Writer::QosYaml(Ros2WriterQos(RosTopicType::kTf)),
             "  depth: 100\n  reliability: reliable\n  durability: volatile\n");
  EXPECT_HAS(Rosbag2Writer::QosYaml(Ros2WriterQos(RosTopicType::kTfStatic)),
             "  depth: 1\n  reliability: reliable\n  durability: transient_local\n");
  // indented for metadata.yaml: every line
  const std::string indented = Rosbag2Writer::QosYaml(Ros2WriterQos(RosTopicType::kTf), "    ");
  EXPECT_EQ(indented.rfind("    - history: keep_last\n", 0), 0u);
  EXPECT_EQ(indented.find("\n  d"), std::string::npos);
}

}  // namespace
}  // namespace penumbra
