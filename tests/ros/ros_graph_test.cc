// ROS names of a world (ros/ros_graph.h): derived topics and frames, overrides, tf parents,
// rigid mounts and clashes.
#include "penumbra/ros/ros_graph.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "penumbra/core/error.h"
#include "penumbra/world/ros_config.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

// a hand-made composed model: world, r/trunk (free joint), r/mount (welded to the trunk),
// r/leg (hinge), and for a second robot q/trunk (free joint); a static box/base
ModelInfo Model() {
  ModelInfo m;
  m.body_names = {"world", "r/trunk", "r/mount", "r/leg", "q/trunk", "box/base"};
  m.body_parent = {-1, 0, 1, 1, 0, 0};
  JointInfo free;
  free.name = "r/root";
  free.type = JointInfo::Type::kFree;
  free.body = 1;
  free.qpos_adr = 0;
  free.dof_adr = 0;
  JointInfo hinge;
  hinge.name = "r/knee";
  hinge.type = JointInfo::Type::kHinge;
  hinge.body = 3;
  hinge.qpos_adr = 7;
  hinge.dof_adr = 6;
  JointInfo qfree = free;
  qfree.name = "q/root";
  qfree.body = 4;
  qfree.qpos_adr = 8;
  qfree.dof_adr = 7;
  m.joints = {free, hinge, qfree};
  m.nq = 15;
  m.nv = 13;
  return m;
}

RosSensorMount Camera(const std::string& name, int body) {
  RosSensorMount c;
  c.name = name;
  c.kind = RosSensorKind::kCamera;
  c.body = body;
  c.rgb = true;
  return c;
}

class RosGraphTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("penumbra_ros_graph_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    std::ofstream(dir_ / "m.xml") << "<mujoco><worldbody><body name=\"trunk\"><freejoint/>"
                                     "<geom size=\"0.1\"/></body></worldbody></mujoco>";
  }
  void TearDown() override { fs::remove_all(dir_); }
  // the world file (written, so that LoadRosConfig reads its `ros:` again)
  WorldConfig World(const std::string& robots, const std::string& extra = "") {
    std::ofstream(dir_ / "world.yaml") << robots << "models:\n  - {name: box, file: m.xml}\n"
                                       << extra;
    return LoadWorldFile((dir_ / "world.yaml").string());
  }
  RosGraph Build(const WorldConfig& w, const std::vector<RosSensorMount>& sensors,
                 const std::vector<std::string>& mocap = {}) {
    return BuildRosGraph(w, LoadRosConfig(w), Model(), sensors, mocap);
  }
  fs::path dir_;
};

const char* kOneRobot = "robots:\n  - {name: r, file: m.xml}\n";
const char* kTwoRobots = "robots:\n  - {name: r, file: m.xml}\n  - {name: q, file: m.xml}\n";

TEST_F(RosGraphTest, DerivesNamesForOneRobot) {
  RosSensorMount imu;
  imu.name = "imu-1";
  imu.kind = RosSensorKind::kImu;
  imu.body = 1;
  RosSensorMount lidar;
  lidar.name = "roof";
  lidar.kind = RosSensorKind::kLidar;
  lidar.body = 5;
  const RosGraph g = Build(
      World(kOneRobot), {Camera("front", 2), Camera("leg_cam", 3), Camera("side", 0), imu, lidar},
      {"box/base"});
  ASSERT_EQ(g.robots.size(), 1u);
  const RosRobotGraph& r = g.robots[0];
  EXPECT_EQ(r.base_body, 1);  // the model's first body (no controller)
  EXPECT_EQ(r.base_frame, "base_link");
  EXPECT_EQ(r.odom_frame, "odom");
  EXPECT_EQ(r.odom_topic, "/r/odom");
  EXPECT_EQ(r.joint_states_topic, "/r/joint_states");
  EXPECT_EQ(r.cmd_vel_topic, "/r/cmd_vel");
  EXPECT_EQ(r.joints, std::vector<int>{1});  // the hinge; free joints are not joint states

  const RosSensorGraph* front = g.FindSensor("front");
  ASSERT_NE(front, nullptr);
  EXPECT_EQ(front->robot, 0);
  EXPECT_EQ(front->image_topic, "/r/front/image_raw");
  EXPECT_EQ(front->info_topic, "/r/front/camera_info");
  EXPECT_EQ(front->depth_image_topic, "/r/front/depth/image_raw");
  EXPECT_EQ(front->frame_id, "front/optical");
  EXPECT_EQ(front->parent_frame, "base_link");
  EXPECT_TRUE(front->rigid_to_parent);                     // the mount is welded to the trunk
  EXPECT_FALSE(g.FindSensor("leg_cam")->rigid_to_parent);  // behind the knee
  const RosSensorGraph* side = g.FindSensor("side");
  EXPECT_EQ(side->robot, -1);
  EXPECT_EQ(side->image_topic, "/side/image_raw");
  EXPECT_EQ(side->parent_frame, "map");
  EXPECT_TRUE(side->rigid_to_parent);
  EXPECT_EQ(g.FindSensor("imu-1")->imu_topic, "/r/imu_1/data");
  EXPECT_EQ(g.FindSensor("imu-1")->frame_id, "imu-1");
  // on a mocap body: moves in the map
  EXPECT_EQ(g.FindSensor("roof")->points_topic, "/roof/points");
  EXPECT_FALSE(g.FindSensor("roof")->rigid_to_parent);
  ASSERT_EQ(g.mocap_topics.size(), 1u);
  EXPECT_EQ(g.mocap_topics[0], "/mocap/box/base/pose");
  EXPECT_EQ(g.PublishedTopics().front(), "/clock");
}

TEST_F(RosGraphTest, SeveralRobotsPrefixFrames) {
  const RosGraph g = Build(World(kTwoRobots), {Camera("front", 2), Camera("qcam", 4)});
  ASSERT_EQ(g.robots.size(), 2u);
  EXPECT_EQ(g.robots[0].base_frame, "r/base_link");
  EXPECT_EQ(g.robots[1].odom_frame, "q/odom");
  EXPECT_EQ(g.robots[1].base_body, 4);
  EXPECT_EQ(g.FindSensor("qcam")->parent_frame, "q/base_link");
  EXPECT_EQ(g.FindSensor("qcam")->image_topic, "/q/qcam/image_raw");
}

TEST_F(RosGraphTest, OverridesFromTheWorldFile) {
  const WorldConfig w = World(kOneRobot,
                              "cameras:\n  - {name: front, attach: r/trunk}\n"
                              "ros:\n  namespace: /sim\n  map_frame: world\n"
                              "  robots:\n    r: {base_body: mount, base_frame: body, "
                              "odom_frame: r_odom, namespace: dog}\n"
                              "  sensors:\n    front: {topic: /camera, frame_id: cam}\n");
  const RosGraph g = Build(w, {Camera("front", 2), Camera("side", 0)});
  EXPECT_EQ(g.map_frame, "world");
  EXPECT_EQ(g.robots[0].base_body, 2);
  EXPECT_EQ(g.robots[0].base_frame, "body");
  EXPECT_EQ(g.robots[0].odom_topic, "/sim/dog/odom");
  EXPECT_EQ(g.FindSensor("front")->image_topic, "/camera/image_raw");  // absolute topic
  EXPECT_EQ(g.FindSensor("front")->frame_id, "cam");
  EXPECT_EQ(g.FindSensor("side")->image_topic, "/sim/side/image_raw");
  EXPECT_EQ(g.FindSensor("side")->parent_frame, "world");
}

TEST_F(RosGraphTest, ErrorsNameTheKey) {
  const WorldConfig bad_body = World(kOneRobot, "ros:\n  robots:\n    r: {base_body: tail}\n");
  try {
    Build(bad_body, {});
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "ros.robots.r.base_body");
    EXPECT_NE(std::string(e.what()).find("no body 'tail'"), std::string::npos) << e.what();
  }
  // two sensors on one topic
  const WorldConfig clash = World(kOneRobot,
                                  "cameras:\n  - {name: a, attach: world}\n"
                                  "  - {name: b, attach: world}\n"
                                  "ros:\n  sensors:\n    b: {topic: a}\n");
  try {
    Build(clash, {Camera("a", 0), Camera("b", 0)});
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("topic '/a/image_raw' is used by both sensor 'a' and "
                                         "sensor 'b'"),
              std::string::npos)
        << e.what();
  }
  // an MJCF camera override the model lacks
  const WorldConfig mjcf = World(kOneRobot, "ros:\n  sensors:\n    r/head: {topic: head}\n");
  EXPECT_THROW(Build(mjcf, {}), ConfigError);
}

TEST(RosNameOf, MakesValidNames) {
  EXPECT_EQ(RosNameOf("front-left"), "front_left");
  EXPECT_EQ(RosNameOf("quadruped/front"), "quadruped/front");
  EXPECT_EQ(RosNameOf("3d_cam"), "_3d_cam");
  EXPECT_EQ(JoinRosName("", "x"), "/x");
  EXPECT_EQ(JoinRosName("/sim/", "x/y"), "/sim/x/y");
  EXPECT_EQ(JoinRosName("sim", "x"), "/sim/x");
  EXPECT_EQ(JoinRosName("/sim", "/abs"), "/abs");
}

}  // namespace
}  // namespace penumbra
