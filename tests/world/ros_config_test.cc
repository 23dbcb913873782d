// the world file's `ros:` section (world/ros_config.h): reading, validation and error lines.
#include "penumbra/world/ros_config.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "penumbra/core/error.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

class RosConfigTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("penumbra_ros_config_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    std::ofstream(dir_ / "m.xml") << "<mujoco><worldbody><body name=\"b\"><freejoint/>"
                                     "<geom size=\"0.1\"/></body></worldbody></mujoco>";
  }
  void TearDown() override { fs::remove_all(dir_); }
  // lines 1-3: the robot, 4-5: a camera; `text` starts on line 6
  WorldConfig Parse(const std::string& text) {
    std::ofstream(dir_ / "world.yaml")
        << "robots:\n  - name: r\n    file: m.xml\ncameras:\n  - {name: cam, attach: r/b}\n"
        << text;
    return LoadWorldFile((dir_ / "world.yaml").string());
  }
  std::string Error(const std::string& text) {
    try {
      Parse(text);
    } catch (const ConfigError& e) {
      return e.what();
    }
    return "";
  }
  fs::path dir_;
};

TEST_F(RosConfigTest, DefaultsWithoutSection) {
  const RosConfig ros = LoadRosConfig(Parse(""));
  EXPECT_EQ(ros.ns, "");
  EXPECT_EQ(ros.map_frame, "map");
  EXPECT_DOUBLE_EQ(ros.state_rate_hz, 50);
  EXPECT_TRUE(ros.robots.empty());
  EXPECT_TRUE(ros.sensors.empty());
  EXPECT_EQ(LoadRosConfig(WorldConfig{}).map_frame, "map");
}

TEST_F(RosConfigTest, ReadsEveryKey) {
  const RosConfig ros = LoadRosConfig(
      Parse("ros:\n"
            "  namespace: /sim\n"
            "  map_frame: world\n"
            "  state_rate_hz: 100\n"
            "  robots:\n"
            "    r: {base_body: b, base_frame: r_base, odom_frame: r_odom, namespace: robot1}\n"
            "  sensors:\n"
            "    cam: {topic: camera, frame_id: cam_optical}\n"));
  EXPECT_EQ(ros.ns, "/sim");
  EXPECT_EQ(ros.map_frame, "world");
  EXPECT_DOUBLE_EQ(ros.state_rate_hz, 100);
  ASSERT_EQ(ros.robots.size(), 1u);
  EXPECT_EQ(ros.robots[0].robot, "r");
  EXPECT_EQ(ros.robots[0].base_body, "b");
  EXPECT_EQ(ros.robots[0].base_frame, "r_base");
  EXPECT_EQ(ros.robots[0].odom_frame, "r_odom");
  EXPECT_EQ(ros.robots[0].ns, "robot1");
  ASSERT_EQ(ros.sensors.size(), 1u);
  EXPECT_EQ(ros.sensors[0].topic, "camera");
  EXPECT_EQ(ros.sensors[0].frame_id, "cam_optical");
}

TEST_F(RosConfigTest, ErrorsNameLineAndKey) {
  EXPECT_NE(Error("ros:\n  nspace: /x\n").find("world.yaml:7: "), std::string::npos);
  EXPECT_NE(Error("ros:\n  nspace: /x\n").find("unknown key 'nspace'"), std::string::npos);
  const std::string bad_topic = Error("ros:\n  sensors:\n    cam: {topic: 'a b'}\n");
  EXPECT_NE(bad_topic.find("world.yaml:8: ros.sensors.cam.topic"), std::string::npos) << bad_topic;
  EXPECT_NE(bad_topic.find("ros.sensors.cam.topic"), std::string::npos) << bad_topic;
  EXPECT_NE(bad_topic.find("not a ROS graph name"), std::string::npos) << bad_topic;
  const std::string rate = Error("ros:\n  state_rate_hz: 0\n");
  EXPECT_NE(rate.find("ros.state_rate_hz"), std::string::npos) << rate;
  EXPECT_NE(rate.find("(0, 1000]"), std::string::npos) << rate;
  const std::string robot = Error("ros:\n  robots:\n    rover: {}\n");
  EXPECT_NE(robot.find("'rover' is not a robot of the world; expected one of: r"),
            std::string::npos)
      << robot;
  const std::string sensor = Error("ros:\n  sensors:\n    lidar: {}\n");
  EXPECT_NE(sensor.find("expected one of: cam"), std::string::npos) << sensor;
  const std::string frame = Error("ros:\n  robots:\n    r: {base_frame: /base}\n");
  EXPECT_NE(frame.find("not a tf frame id"), std::string::npos) << frame;
  const std::string body = Error("ros:\n  robots:\n    r: {base_body: r/b}\n");
  EXPECT_NE(body.find("model-local body name"), std::string::npos) << body;
  // an MJCF camera is checked once the model is composed
  EXPECT_EQ(Error("ros:\n  sensors:\n    r/head: {topic: head}\n"), "");
}

TEST(RosNames, GraphNameRules) {
  for (const char* ok : {"/a", "a", "/a/b_c", "~private", "/ns/cam0/image_raw", "a/_b"})
    EXPECT_TRUE(IsValidRosName(ok)) << ok;
  for (const char* bad : {"", "/", "a/", "a//b", "1a", "/a/1b", "a-b", "a b", "a.b"})
    EXPECT_FALSE(IsValidRosName(bad)) << bad;
  for (const char* ok : {"base_link", "front/optical", "go1/base_link", "cam-1.optical"})
    EXPECT_TRUE(IsValidFrameId(ok)) << ok;
  for (const char* bad : {"", "/base_link", "a b"}) EXPECT_FALSE(IsValidFrameId(bad)) << bad;
}

}  // namespace
}  // namespace penumbra
