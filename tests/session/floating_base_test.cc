// floating base: a URDF's root link is welded to the world by MuJoCo's
// importer; `floating_base: true` makes it a free body with the root link's inertial.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "common/temp_dir.h"
#include "penumbra/core/error.h"
#include "penumbra/session/session.h"

namespace penumbra {
namespace {

const char* kFloatingUrdf =
    "<robot name=\"bot\">\n"
    "  <link name=\"base\">\n"
    "    <inertial><origin xyz=\"0.01 0 0\" rpy=\"0 0 0\"/><mass value=\"2\"/>\n"
    "      <inertia ixx=\"0.02\" iyy=\"0.03\" izz=\"0.04\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/>"
    "</inertial>\n"
    "    <collision><geometry><box size=\"0.4 0.3 0.1\"/></geometry></collision>\n"
    "  </link>\n"
    "  <link name=\"arm\">\n"
    "    <inertial><mass value=\"1\"/>\n"
    "      <inertia ixx=\"0.01\" iyy=\"0.01\" izz=\"0.01\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/>"
    "</inertial>\n"
    "    <collision><geometry><cylinder radius=\"0.05\" length=\"0.3\"/></geometry></collision>\n"
    "  </link>\n"
    "  <joint name=\"j1\" type=\"revolute\"><parent link=\"base\"/><child link=\"arm\"/>\n"
    "    <origin xyz=\"0 0 0.2\"/><axis xyz=\"0 1 0\"/>"
    "<limit lower=\"-1\" upper=\"1\" effort=\"10\" velocity=\"1\"/></joint>\n"
    "</robot>\n";

struct Bot {
  penumbra::testing::TempDir dir;
  std::string world;
  explicit Bot(const std::string& floating, const std::string& urdf = kFloatingUrdf) {
    dir.Write("bot.urdf", urdf);
    dir.Write("floor.xml",
              "<mujoco><worldbody><geom type=\"plane\" size=\"0 0 0.05\"/></worldbody></mujoco>\n");
    world = dir.Write("world.yaml",
                      "models:\n  - {name: floor, file: floor.xml}\n"
                      "robots:\n  - {name: bot, file: bot.urdf, pose: {xyz: [0, 0, 1]}" +
                          floating + "}\n");
  }
};

double BaseHeightAfter(Simulation* sim, double t_sec) {
  const auto& names = sim->model_info().body_names;
  const int arm =
      static_cast<int>(std::find(names.begin(), names.end(), "bot/arm") - names.begin());
  EXPECT_LT(arm, static_cast<int>(names.size()));
  while (sim->time() < t_sec - 1e-9) sim->Step();
  return sim->Snapshot().X_WB[arm].translation().z() - 0.2;
}

TEST(FloatingBase, TheUrdfRootLinkBecomesAFreeBodyWithItsInertial) {
  Bot bot(", floating_base: true");
  SessionOptions options;
  options.build_renderer = false;
  Session session(LoadWorldFile(bot.world), options);
  Simulation& sim = session.sim();
  const ModelInfo& info = sim.model_info();
  const int j = info.Find(ModelObject::kJoint, "bot/floating_base");
  ASSERT_GE(j, 0);
  EXPECT_EQ(info.joints[j].type, JointInfo::Type::kFree);
  const auto& names = info.body_names;
  const int base =
      static_cast<int>(std::find(names.begin(), names.end(), "bot/base") - names.begin());
  ASSERT_LT(base, static_cast<int>(names.size()));
  EXPECT_EQ(info.body_mass[base], 2.0);
  EXPECT_NEAR(info.body_X_BI[base].translation().x(), 0.01, 1e-12);
  // free fall for 0.3 s from 1 m: 0.5 g t^2 = 0.44 m
  EXPECT_NEAR(BaseHeightAfter(&sim, 0.3), 1.0 - 0.5 * 9.81 * 0.09, 0.01);
}

// with the URDF's own <mujoco> extension fusing static links, MuJoCo's importer puts the root
// link's geoms into the world body and drops its inertial: the composer rebuilds the body
TEST(FloatingBase, AFusedRootLinkIsRebuiltWithTheUrdfInertial) {
  std::string urdf = kFloatingUrdf;
  urdf.insert(urdf.find("  <link name=\"base\">"),
              "  <mujoco><compiler fusestatic=\"true\" discardvisual=\"false\"/></mujoco>\n");
  Bot bot(", floating_base: true", urdf);
  SessionOptions options;
  options.build_renderer = false;
  Session session(LoadWorldFile(bot.world), options);
  const ModelInfo& info = session.sim().model_info();
  const auto& names = info.body_names;
  const int base =
      static_cast<int>(std::find(names.begin(), names.end(), "bot/base") - names.begin());
  ASSERT_LT(base, static_cast<int>(names.size()));
  EXPECT_EQ(info.body_mass[base], 2.0);
  EXPECT_NEAR(info.body_X_BI[base].translation().x(), 0.01, 1e-12);
  EXPECT_NEAR(BaseHeightAfter(&session.sim(), 0.3), 1.0 - 0.5 * 9.81 * 0.09, 0.01);
}

TEST(FloatingBase, WithoutItTheRootLinkStaysWelded) {
  Bot bot("");
  SessionOptions options;
  options.build_renderer = false;
  Session session(LoadWorldFile(bot.world), options);
  EXPECT_LT(session.sim().model_info().Find(ModelObject::kJoint, "bot/floating_base"), 0);
  EXPECT_NEAR(BaseHeightAfter(&session.sim(), 0.3), 1.0, 1e-9);
}

TEST(FloatingBase, IsForUrdfModelsOnly) {
  penumbra::testing::TempDir dir;
  dir.Write("m.xml",
            "<mujoco><worldbody><body><freejoint/><geom size=\"0.1\"/></body>"
            "</worldbody></mujoco>\n");
  const std::string world =
      dir.Write("world.yaml", "robots:\n  - {name: m, file: m.xml, floating_base: true}\n");
  SessionOptions options;
  options.build_renderer = false;
  try {
    Session session(LoadWorldFile(world), options);
    ADD_FAILURE() << "floating_base accepted on MJCF";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "robots[0].floating_base");
    EXPECT_NE(std::string(e.what()).find("expected floating_base only for URDF models"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace penumbra
