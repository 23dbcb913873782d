// a foreign robot through a world file only: a third-party-style quadruped with
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
  // the key's qpos is the model's start (trunk at z = 0.285, knees at -1.8 rad), settled on
  // its feet before t = 0 (docs/world-file.md "Robots start settled"): the knees give a little
  const int calf = info.Find(ModelObject::kJoint, "dog/FR_calf");
  ASSERT_GE(calf, 0);
  EXPECT_NEAR(sim.GetState().qpos[info.joints[calf].qpos_adr], -1.8, 0.02);
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
  std::printf("[ measured ] TCP from (%.3f, %.3f, %.3f) to (%.4f, %.4f, %.4f), error %.3e m\n",
              start.x(), start.y(), start.z(), end.x(), end.y(), end.z(), (end - target).norm());
  EXPECT_GT((start - target).norm(), 0.1);
  EXPECT_LT((end - target).norm(), 0.01);
}

}  // namespace
}  // namespace penumbra

namespace penumbra {
namespace {

// a stand-in of Menagerie's Go2 structure: the bundled quadruped with its foot sites and
// touch sensors removed, foot geoms named FR, FL, RR, RL with no pos of their own, positioned
// by a nested default class (<default class="collision"><default class="foot"><geom pos=...>),
// as unitree_go2/go2.xml writes them
std::string Go2StyleQuadruped() {
  std::ifstream f(std::string(PENUMBRA_SOURCE_DIR) + "/worlds/models/quadruped.xml");
  std::stringstream ss;
  ss << f.rdbuf();
  std::string xml = ss.str();
  xml = std::regex_replace(xml, std::regex("<site name=\"(FR|FL|RR|RL)_foot\"[^>]*/>"), "");
  xml = std::regex_replace(xml, std::regex("<touch name=\"(FR|FL|RR|RL)_foot_touch\"[^>]*/>"), "");
  xml = std::regex_replace(
      xml,
      std::regex("<geom name=\"(FR|FL|RR|RL)_foot\" class=\"go1_foot\" size=\"0.02\" "
                 "pos=\"0 0 -0.213\"/>"),
      "<geom name=\"$1\" class=\"foot\"/>");
  xml = std::regex_replace(
      xml, std::regex("<default class=\"go1_collision\">\\s*<geom group=\"0\"/>\\s*</default>"),
      "<default class=\"go1_collision\"><geom group=\"0\"/>"
      "<default class=\"foot\"><geom type=\"sphere\" size=\"0.02\" pos=\"0 0 -0.213\" "
      "material=\"rubber\" friction=\"0.8 0.02 0.01\" priority=\"1\" solref=\"0.01 1\"/>"
      "</default></default>");
  EXPECT_NE(xml.find("<geom name=\"RL\" class=\"foot\"/>"), std::string::npos);
  EXPECT_NE(xml.find("<default class=\"foot\">"), std::string::npos);
  EXPECT_EQ(xml.find("pos=\"0 0 -0.213\" size=\"0.025\""), std::string::npos);
  return xml;
}

// the documented Go2 walkthrough (sites at the foot geoms) on a model whose foot
// geoms get their pos from a default class: the sites land at the foot centres (0.213 m
// below the knee axis, not on it) and trot_gait walks
TEST(ForeignRobotWorld, Go2StyleFootGeomsPositionedByADefaultClassGiveFootSitesThatWalk) {
  penumbra::testing::TempDir dir;
  dir.Write("floor.xml",
            "<mujoco><worldbody><geom name=\"ground\" type=\"plane\" size=\"0 0 0.05\"/>"
            "</worldbody></mujoco>\n");
  dir.Write("go2/go2.xml", Go2StyleQuadruped());
  std::string legs;
  for (const char* l : {"FR", "FL", "RR", "RL"}) {
    const std::string s = l;
    legs += "        " + s + ": {hip: " + s + "_hip, thigh: " + s + "_thigh, calf: " + s +
            "_calf, foot: " + s + "_tip}\n";
  }
  const std::string world = dir.Write("world.yaml",
                                      "duration_sec: 3\n"
                                      "models:\n"
                                      "  - {name: floor, file: floor.xml}\n"
                                      "robots:\n"
                                      "  - name: dog\n"
                                      "    file: go2/go2.xml\n"
                                      "    initial_keyframe: stand\n"
                                      "    sites:\n"
                                      "      - {name: FR_tip, geom: FR}\n"
                                      "      - {name: FL_tip, geom: FL}\n"
                                      "      - {name: RR_tip, geom: RR}\n"
                                      "      - {name: RL_tip, geom: RL}\n"
                                      "    controller:\n"
                                      "      type: trot_gait\n"
                                      "      base_body: trunk\n"
                                      "      legs:\n" +
                                          legs + "      commands: [{t: 0, vx: 0.5}]\n");
  SessionOptions options;
  options.build_renderer = false;
  Session session(LoadWorldFile(world), options);
  Simulation& sim = session.sim();
  const ModelInfo& info = sim.model_info();
  for (const char* l : {"FR", "FL", "RR", "RL"}) {
    const int site = info.Find(ModelObject::kSite, std::string("dog/") + l + "_tip");
    ASSERT_GE(site, 0) << l;
    EXPECT_EQ(info.body_names[info.site_body[site]], std::string("dog/") + l + "_calf");
    EXPECT_NEAR(info.site_X_BS[site].translation().z(), -0.213, 1e-12) << l;
    EXPECT_NEAR(info.site_X_BS[site].translation().head<2>().norm(), 0, 1e-12) << l;
  }
  const auto& names = info.body_names;
  const int trunk =
      static_cast<int>(std::find(names.begin(), names.end(), "dog/trunk") - names.begin());
  ASSERT_LT(trunk, static_cast<int>(names.size()));
  const double x0 = sim.Snapshot().X_WB[trunk].translation().x();
  while (sim.time() < 3.0 - 1e-9) sim.Step();
  const Pose X = sim.Snapshot().X_WB[trunk];
  const double dx = X.translation().x() - x0;
  std::printf("[ measured ] Go2-style foot geoms (pos from a default class): %.3f m in 3 s\n", dx);
  EXPECT_GT(dx, 1.1);
  EXPECT_GT(X.linear()(2, 2), 0.95);
}

}  // namespace
}  // namespace penumbra

namespace penumbra {
namespace {

// the bundled quadruped with every knee joint turned round (axis 0 -1 0, so its angles are
// the negatives of the Unitree convention's: ref +1.8, range [0.888, 2.818]); same rest pose
std::string InvertedKneeQuadruped() {
  std::ifstream f(std::string(PENUMBRA_SOURCE_DIR) + "/worlds/models/quadruped.xml");
  std::stringstream ss;
  ss << f.rdbuf();
  std::string xml = ss.str();
  xml = std::regex_replace(
      xml, std::regex("<joint name=\"(FR|FL|RR|RL)_calf\" class=\"go1_calf\" ref=\"-1.8\"/>"),
      "<joint name=\"$1_calf\" class=\"go1_calf\" axis=\"0 -1 0\" range=\"0.888 2.818\" "
      "ref=\"1.8\"/>");
  xml = std::regex_replace(xml, std::regex("<key name=\"stand\"[^>]*/>"), "");
  EXPECT_NE(xml.find("<joint name=\"RL_calf\" class=\"go1_calf\" axis=\"0 -1 0\""),
            std::string::npos);
  return xml;
}

std::string InvertedKneeWorld(const std::string& signs) {
  std::string legs;
  for (const char* l : {"FR", "FL", "RR", "RL"}) {
    const std::string s = l;
    legs += "        " + s + ": {hip: " + s + "_hip, thigh: " + s + "_thigh, calf: " + s +
            "_calf, foot: " + s + "_foot" + signs + "}\n";
  }
  return "duration_sec: 3\n"
         "models:\n"
         "  - {name: floor, file: floor.xml}\n"
         "robots:\n"
         "  - name: dog\n"
         "    file: dog.xml\n"
         "    controller:\n"
         "      type: trot_gait\n"
         "      base_body: trunk\n"
         "      legs:\n" +
         legs + "      commands: [{t: 0, vx: 0.5}]\n";
}

// a quadruped whose knee joints turn the other way than trot_gait's convention,
// run without `signs`, gets a warning at start-up naming the knee joints and the setting;
// with the setting it names, no warning and it walks
TEST(ForeignRobotWorld, InvertedKneeSignsAreWarnedAtStartWithTheSettingThatFixesThem) {
  penumbra::testing::TempDir dir;
  dir.Write("floor.xml",
            "<mujoco><worldbody><geom name=\"ground\" type=\"plane\" size=\"0 0 0.05\"/>"
            "</worldbody></mujoco>\n");
  dir.Write("dog.xml", InvertedKneeQuadruped());
  SessionOptions options;
  options.build_renderer = false;
  {
    Session session(LoadWorldFile(dir.Write("world.yaml", InvertedKneeWorld(""))), options);
    Simulation& sim = session.sim();
    sim.RunDueControllers();  // the first update: the start-pose check
    std::string all;
    for (const std::string& w : sim.TakeWarnings()) all += w + "\n";
    for (const char* l : {"FR", "FL", "RR", "RL"}) {
      const std::string leg = l;
      EXPECT_NE(all.find("legs." + leg + ": joint(s) 'dog/" + leg +
                         "_calf' move the foot opposite to trot_gait's leg convention"),
                std::string::npos)
          << all;
      EXPECT_NE(all.find("set legs." + leg + ".signs: [1, 1, -1] (now [1, 1, 1])"),
                std::string::npos)
          << all;
      EXPECT_NE(all.find("legs." + leg + ": in the start pose the knee 'dog/" + leg + "_calf'"),
                std::string::npos)
          << all;
    }
    EXPECT_EQ(all.find("_hip'"), std::string::npos) << all;
    EXPECT_EQ(all.find("_thigh'"), std::string::npos) << all;
  }
  Session session(LoadWorldFile(dir.Write("world2.yaml", InvertedKneeWorld(", signs: [1, 1, -1]"))),
                  options);
  Simulation& sim = session.sim();
  const auto& names = sim.model_info().body_names;
  const int trunk =
      static_cast<int>(std::find(names.begin(), names.end(), "dog/trunk") - names.begin());
  ASSERT_LT(trunk, static_cast<int>(names.size()));
  const double x0 = sim.Snapshot().X_WB[trunk].translation().x();
  std::string all;
  while (sim.time() < 3.0 - 1e-9) {
    sim.Step();
    for (const std::string& w : sim.TakeWarnings()) all += w + "\n";
  }
  EXPECT_EQ(all.find("trot_gait"), std::string::npos) << all;
  const Pose X = sim.Snapshot().X_WB[trunk];
  std::printf("[ measured ] inverted knees with signs [1, 1, -1]: %.3f m in 3 s\n",
              X.translation().x() - x0);
  EXPECT_GT(X.translation().x() - x0, 1.1);
  EXPECT_GT(X.linear()(2, 2), 0.95);
}

}  // namespace
}  // namespace penumbra
