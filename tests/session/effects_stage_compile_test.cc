// EffectsStage compiles the composed model itself only for an adversity preset (its planner
// needs the static scene); the world's own agents are checked against the run's model.
#include <gtest/gtest.h>
#include <tinyxml2.h>

#include <string>

#include "common/temp_dir.h"
#include "penumbra/core/error.h"
#include "penumbra/physics/simulation.h"
#include "penumbra/session/effects_stage.h"
#include "penumbra/session/world_composer.h"

namespace penumbra {
namespace {

constexpr const char* kFloor = R"(<mujoco model="floor">
  <worldbody>
    <geom name="floor" type="plane" size="5 5 0.1"/>
  </worldbody>
</mujoco>)";

// the composed floor with what MuJoCo refuses to compile: a moving body without mass
ComposedScene ComposeMassless(const WorldConfig& world) {
  ComposedScene composed = ComposeWorld(world.models, ComposeOptions{});
  tinyxml2::XMLElement* worldbody =
      composed.document->RootElement()->FirstChildElement("worldbody");
  tinyxml2::XMLElement* ghost = worldbody->InsertNewChildElement("body");
  ghost->SetAttribute("name", "ghost");
  ghost->SetAttribute("pos", "0 0 1");
  ghost->InsertNewChildElement("joint")->SetAttribute("name", "hinge");
  return composed;
}

WorldConfig MasslessWorld(const penumbra::testing::TempDir& dir) {
  WorldConfig world;
  world.file = "w.yaml";
  ModelConfig m;
  m.name = "m";
  m.file = dir.Write("floor.xml", kFloor);
  world.models.push_back(m);
  AgentConfig a;
  a.name = "walker";
  a.kind = AgentKind::kPerson;
  a.waypoints = {{-1, 0}, {1, 0}};
  world.agents = {a};
  return world;
}

TEST(EffectsStageCompile, AgentsWithoutAPresetDoNotCompileTheModel) {
  const penumbra::testing::TempDir dir;
  const WorldConfig world = MasslessWorld(dir);
  ComposedScene composed = ComposeMassless(world);
  // a compile here would throw MuJoCo's error
  EffectsStage stage(world, &composed);
  EXPECT_EQ(stage.agents().size(), 1u);
  EXPECT_NE(composed.Xml().find("agents/walker"), std::string::npos);
  EXPECT_THROW(Simulation::LoadFromString(composed.Xml()), ConfigError);
}

TEST(EffectsStageCompile, APresetPlansOnACompiledProbe) {
  const penumbra::testing::TempDir dir;
  const WorldConfig world = MasslessWorld(dir);
  ComposedScene composed = ComposeMassless(world);
  try {
    EffectsStage stage(world, &composed, "minor");
    FAIL() << "expected MuJoCo's error from the planner's probe compile";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("MuJoCo could not load the model"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace penumbra
