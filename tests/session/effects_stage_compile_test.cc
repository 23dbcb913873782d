// EffectsStage compiles the composed model itself only for an adversity preset (its planner
// needs the static scene); the world's own agents are checked against the run's model.
#include <gtest/gtest.h>

#include <string>

#include "common/temp_dir.h"
#include "penumbra/compose/scene_composer.h"
#include "penumbra/core/error.h"
#include "penumbra/physics/simulation.h"
#include "penumbra/session/effects_stage.h"

namespace penumbra {
namespace {

// composes (every name defined, every reference resolved) but MuJoCo refuses to compile it:
// a moving body without mass
constexpr const char* kMassless = R"(<mujoco model="massless">
  <worldbody>
    <geom name="floor" type="plane" size="5 5 0.1"/>
    <body name="ghost" pos="0 0 1"><joint name="hinge" type="hinge"/></body>
  </worldbody>
</mujoco>)";

WorldConfig MasslessWorld(const penumbra::testing::TempDir& dir) {
  WorldConfig world;
  world.file = "w.yaml";
  ModelConfig m;
  m.name = "m";
  m.file = dir.Write("massless.xml", kMassless);
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
  ComposedScene composed = ComposeWorld(world.models, ComposeOptions{});
  // a compile here would throw MuJoCo's error
  EffectsStage stage(world, &composed);
  EXPECT_EQ(stage.agents().size(), 1u);
  EXPECT_NE(composed.Xml().find("agents/walker"), std::string::npos);
  EXPECT_THROW(Simulation::LoadFromString(composed.Xml()), ConfigError);
}

TEST(EffectsStageCompile, APresetPlansOnACompiledProbe) {
  const penumbra::testing::TempDir dir;
  const WorldConfig world = MasslessWorld(dir);
  ComposedScene composed = ComposeWorld(world.models, ComposeOptions{});
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
