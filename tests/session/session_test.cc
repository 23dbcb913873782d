// a world loaded once (session/session.h): composed model, simulation with controllers and
// agents, scene, effects and renderer.
#include "penumbra/session/session.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "common/temp_dir.h"
#include "penumbra/compose/agent_bodies.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

std::string WorldPath(const std::string& rel) {
  return (std::filesystem::path(PENUMBRA_SOURCE_DIR) / "worlds" / rel).string();
}

int RobotsWithControllers(const WorldConfig& world) {
  int n = 0;
  for (const ModelConfig& m : world.models) n += m.is_robot && !m.controller.type.empty();
  return n;
}

int BodyIndex(const Simulation& sim, const std::string& name) {
  const std::vector<std::string>& names = sim.model_info().body_names;
  for (size_t b = 0; b < names.size(); ++b)
    if (names[b] == name) return static_cast<int>(b);
  return -1;
}

TEST(Session, LoadsTheDefaultWorldWithItsControllersAndKeepsTheComposedModel) {
  const penumbra::testing::TempDir dir;
  const WorldConfig world = LoadWorldFile(WorldPath("default.yaml"));
  ASSERT_GT(RobotsWithControllers(world), 0);
  SessionOptions options;
  options.composed_xml_path = (dir.path() / "composed.xml").string();
  options.build_renderer = false;
  Session session(world, options);

  // the model was loaded from the file it kept
  EXPECT_EQ(session.sim().source(), options.composed_xml_path);
  const std::string xml = penumbra::testing::ReadAll(options.composed_xml_path);
  EXPECT_NE(xml.find("<mujoco"), std::string::npos);
  EXPECT_EQ(session.sim().num_controllers(), RobotsWithControllers(world));
  EXPECT_EQ(session.sim().step_count(), 0);
  EXPECT_FALSE(session.scene().cameras.empty());
  EXPECT_EQ(session.renderer(), nullptr);
  EXPECT_EQ(session.world().render.seed, world.seed);
  EXPECT_GE(session.timings().compose_sec, 0.0);
}

TEST(Session, WithoutAFileOrControllersAndWithTheRenderer) {
  WorldConfig world = LoadWorldFile(WorldPath("default.yaml"));
  world.render.threads = 1;
  SessionOptions options;
  options.add_controllers = false;
  Session session(world, options);
  EXPECT_EQ(session.sim().source(), "<string>");
  EXPECT_EQ(session.sim().num_controllers(), 0);
  ASSERT_NE(session.renderer(), nullptr);
}

TEST(Session, AgentsAreComposedLabelledAndDrivenAlongTheirPaths) {
  const WorldConfig world = LoadWorldFile(WorldPath("effects/crowd.yaml"));
  ASSERT_FALSE(world.agents.empty());
  SessionOptions options;
  options.build_renderer = false;
  Session session(world, options);
  ASSERT_EQ(session.effects().agents().size(), world.agents.size());

  const std::string body_name = AgentBodyName(world.agents.front().name);
  const int body = BodyIndex(session.sim(), body_name);
  ASSERT_GE(body, 0) << body_name;
  // the scene labels the agent's geoms with its class
  const int scene_body = session.scene().FindBody(body_name);
  ASSERT_GE(scene_body, 0);
  int labelled = 0;
  for (const Geom& g : session.scene().geoms)
    if (g.body == scene_body) labelled += g.semantic_class != 0;
  EXPECT_GT(labelled, 0);
  // the mocap driver moves the body with sim time
  const Pose X0 = session.sim().Snapshot(Simulation::SnapshotContent::kPoses).X_WB[body];
  for (int i = 0; i < 250; ++i) session.sim().Step();
  const Pose X1 = session.sim().Snapshot(Simulation::SnapshotContent::kPoses).X_WB[body];
  EXPECT_GT((X1.translation() - X0.translation()).norm(), 0.05);
}

TEST(Session, AnImuOnAnUnknownBodyIsAConfigErrorNamingIt) {
  WorldConfig world = LoadWorldFile(WorldPath("default.yaml"));
  SensorConfig imu;
  imu.name = "imu_x";
  imu.params = ImuSensorParams{};  // the consumer_mems preset
  imu.body = "no_such_body";
  imu.rate_hz = 100;
  world.sensors.push_back(imu);
  SessionOptions options;
  options.build_renderer = false;
  try {
    Session session(world, options);
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_body"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace penumbra
