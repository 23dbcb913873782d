// issue 17 point 7 acceptance, through a world file only: a third-party-style quadruped with
// position-servo actuators and no foot sites (the bundled quadruped with its motors replaced
// by <position> servos and its foot sites and touch sensors removed) trots with trot_gait,
// its feet added by the world file's `sites:` (at foot geoms, or on the calf bodies with an
// offset), starting from its `stand` key via `initial_keyframe`; and a Panda-class arm with
// servos and no TCP site moved by diff_ik to a target for a world-file TCP site.
#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include "common/temp_dir.h"
#include "penumbra/core/error.h"
#include "penumbra/session/session.h"

namespace penumbra {
namespace {

std::string ForeignQuadruped() {
  std::ifstream f(std::string(PENUMBRA_SOURCE_DIR) + "/worlds/models/quadruped.xml");
  std::stringstream ss;
  ss << f.rdbuf();
  std::string xml = ss.str();
  xml = std::regex_replace(xml, std::regex("<site name=\"(FR|FL|RR|RL)_foot\"[^>]*/>"), "");
  xml = std::regex_replace(xml, std::regex("<touch name=\"(FR|FL|RR|RL)_foot_touch\"[^>]*/>"), "");
  xml = std::regex_replace(xml, std::regex("<motor name="), "<position kp=\"100\" name=");
  EXPECT_EQ(xml.find("_foot\" pos=\"0 0 -0.213\" size=\"0.025\""), std::string::npos);
  EXPECT_EQ(xml.find("<motor name="), std::string::npos);
  return xml;
}

std::string World(const std::string& initial_keyframe) {
  std::string legs;
  for (const char* l : {"FR", "FL", "RR", "RL"}) {
    const std::string s = l;
    legs += "          " + s + ": {hip: " + s + "_hip, thigh: " + s + "_thigh, calf: " + s +
            "_calf, foot: " + s + "_tip}\n";
  }
  return "duration_sec: 3\n"
         "models:\n"
         "  - {name: floor, file: floor.xml}\n"
         "robots:\n"
         "  - name: dog\n"
         "    file: dog.xml\n"
         "    initial_keyframe: " +
         initial_keyframe +
         "\n"
         "    sites:\n"
         "      - {name: FR_tip, geom: FR_foot}\n"
         "      - {name: FL_tip, geom: FL_foot}\n"
         "      - {name: RR_tip, body: RR_calf, pose: {xyz: [0, 0, -0.213]}}\n"
         "      - {name: RL_tip, body: RL_calf, pose: {xyz: [0, 0, -0.213]}}\n"
         "    controller:\n"
         "      type: trot_gait\n"
         "      base_body: trunk\n"
         "      legs:\n" +
         legs + "      commands: [{t: 0, vx: 0.5}]\n";
}

struct Files {
  penumbra::testing::TempDir dir;
  std::string world;
  explicit Files(const std::string& initial_keyframe) {
    dir.Write("floor.xml",
              "<mujoco><worldbody><geom name=\"ground\" type=\"plane\" size=\"0 0 0.05\"/>"
              "</worldbody></mujoco>\n");
    dir.Write("dog.xml", ForeignQuadruped());
    world = dir.Write("world.yaml", World(initial_keyframe));
  }
};

TEST(ForeignRobotWorld, PositionServoQuadrupedWithoutFootSitesTrotsFromTheWorldFile) {
  Files files("stand");
  SessionOptions options;
  options.build_renderer = false;
  Session session(LoadWorldFile(files.world), options);
  Simulation& sim = session.sim();
  const ModelInfo& info = sim.model_info();
  // the key's qpos is the model's start (trunk at z = 0.285, knees at -1.8 rad)
  const int calf = info.Find(ModelObject::kJoint, "dog/FR_calf");
  ASSERT_GE(calf, 0);
  EXPECT_EQ(sim.GetState().qpos[info.joints[calf].qpos_adr], -1.8);
  const auto& names = info.body_names;
  const int trunk =
      static_cast<int>(std::find(names.begin(), names.end(), "dog/trunk") - names.begin());
  ASSERT_LT(trunk, static_cast<int>(names.size()));
  const double x0 = sim.Snapshot().X_WB[trunk].translation().x();
  while (sim.time() < 3.0 - 1e-9) sim.Step();
  const Pose X = sim.Snapshot().X_WB[trunk];
  const double dx = X.translation().x() - x0;
  std::printf("[ measured ] world-file-only foreign quadruped: %.3f m in 3 s at 0.5 m/s\n", dx);
  EXPECT_GT(dx, 1.1);  // the motor model walks 1.35 m (physics ForeignActuators test)
  EXPECT_GT(X.linear()(2, 2), 0.95);
}

TEST(ForeignRobotWorld, AnUnknownInitialKeyframeNamesTheKeyAndTheModelsKeys) {
  Files files("home");
  SessionOptions options;
  options.build_renderer = false;
  try {
    Session session(LoadWorldFile(files.world), options);
    ADD_FAILURE() << "unknown keyframe accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "robots[0].initial_keyframe") << e.what();
    EXPECT_NE(std::string(e.what()).find("no keyframe 'home' in model 'dog'; expected one of "
                                         "its <key> names: stand"),
              std::string::npos)
        << e.what();
  }
}

// the arm half: a Panda-class arm without a TCP site whose joints have Menagerie-Panda style
// servos (<general gainprm=kp biasprm="0 -kp -kv">), moved by diff_ik (output: position) to a
// target given for a TCP that the world file adds on the hand body
std::string ForeignArm() {
  std::ifstream f(std::string(PENUMBRA_SOURCE_DIR) + "/worlds/models/arm/panda_arm.xml");
  std::stringstream ss;
  ss << f.rdbuf();
  std::string xml = ss.str();
  xml = std::regex_replace(xml, std::regex("<site name=\"ee\"[^>]*/>"), "");
  xml = std::regex_replace(
      xml,
      std::regex("<motor (name=\"actuator[1-7]\" class=\"panda\" joint=\"joint[1-7]\") "
                 "ctrlrange=\"[^\"]*\"/>"),
      "<general $1 gainprm=\"2000\" biastype=\"affine\" biasprm=\"0 -2000 -100\" "
      "ctrlrange=\"-3.1 3.1\"/>");
  EXPECT_EQ(xml.find("name=\"ee\""), std::string::npos);
  EXPECT_EQ(xml.find("<motor name=\"actuator"), std::string::npos);
  return xml;
}

TEST(ForeignRobotWorld, ServoArmWithoutATcpSiteMovesWithDiffIkFromTheWorldFile) {
  penumbra::testing::TempDir dir;
  dir.Write("arm/panda.xml", ForeignArm());
  const std::string world = dir.Write(
      "world.yaml",
      // as Menagerie's Panda (implicitfast): implicit integrates the servo damping stably
      "physics: {integrator: implicit}\n"
      "robots:\n"
      "  - name: arm\n"
      "    file: arm/panda.xml\n"
      "    sites:\n"
      "      - {name: tcp, body: hand, pose: {xyz: [0, 0, 0.1034]}}\n"
      "    controller:\n"
      "      type: diff_ik\n"
      "      site: tcp\n"
      "      base_body: link0\n"
      "      joints: [joint1, joint2, joint3, joint4, joint5, joint6, joint7]\n"
      "      actuators: [actuator1, actuator2, actuator3, actuator4, actuator5, actuator6, "
      "actuator7]\n"
      "      output: position\n"
      "      commands:\n"
      "        - {t: 0, move_to: {xyz: [0.45, 0.15, 0.35], rpy_deg: [180, 0, 0]}}\n");
  SessionOptions options;
  options.build_renderer = false;
  Session session(LoadWorldFile(world), options);
  Simulation& sim = session.sim();
  const auto& names = sim.model_info().body_names;
  const int hand =
      static_cast<int>(std::find(names.begin(), names.end(), "arm/hand") - names.begin());
  ASSERT_LT(hand, static_cast<int>(names.size()));
  const auto tcp = [&] {
    return Eigen::Vector3d(sim.Snapshot().X_WB[hand] * Eigen::Vector3d(0, 0, 0.1034));
  };
  const Eigen::Vector3d start = tcp();
  while (sim.time() < 4.0 - 1e-9) sim.Step();
  const Eigen::Vector3d end = tcp();
  const Eigen::Vector3d target(0.45, 0.15, 0.35);
  std::printf("[ measured ] TCP from (%.3f, %.3f, %.3f) to (%.4f, %.4f, %.4f), error %.4f m\n",
              start.x(), start.y(), start.z(), end.x(), end.y(), end.z(), (end - target).norm());
  EXPECT_GT((start - target).norm(), 0.1);
  EXPECT_LT((end - target).norm(), 0.01);
}

}  // namespace
}  // namespace penumbra
