// issue 17 point 7 acceptance, through a world file only: a third-party-style quadruped with
// position-servo actuators and no foot sites (the bundled quadruped with its motors replaced
// by <position> servos and its foot sites and touch sensors removed) trots with trot_gait,
// its feet added by the world file's `sites:` (at foot geoms, or on the calf bodies with an
// offset), starting from its `stand` key via `initial_keyframe`.
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

}  // namespace
}  // namespace penumbra
