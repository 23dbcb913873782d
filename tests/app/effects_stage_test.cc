// adversity presets placed in the default world (session/effects_stage.h).
#include "penumbra/session/effects_stage.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "common/temp_dir.h"
#include "penumbra/app/cli.h"
#include "penumbra/core/error.h"
#include "penumbra/physics/simulation.h"
#include "penumbra/run/runner.h"
#include "penumbra/session/floor_map.h"
#include "penumbra/session/world_composer.h"

namespace penumbra {
namespace {

const std::string kDefaultWorld = std::string(PENUMBRA_SOURCE_DIR) + "/worlds/default.yaml";

struct Planned {
  std::vector<EffectConfig> effects;
  std::vector<AgentConfig> agents;
};

Planned Plan(const std::string& preset, uint64_t seed) {
  WorldConfig world = LoadWorldFile(kDefaultWorld);
  world.seed = seed;
  ComposeOptions opts;
  ComposedScene composed = ComposeWorld(world.models, opts);
  EffectsStage stage(world, &composed, preset);
  return {stage.effects(), stage.agents()};
}

std::vector<std::string> Names(const Planned& p) {
  std::vector<std::string> out;
  for (const EffectConfig& e : p.effects) out.push_back(e.name);
  for (const AgentConfig& a : p.agents) out.push_back(a.name);
  return out;
}

TEST(AdversityPlan, NoneAddsNothingMinorAndMajorAddTheirParts) {
  EXPECT_TRUE(Names(Plan("none", 7)).empty());
  const Planned minor = Plan("minor", 7);
  EXPECT_EQ(Names(minor), (std::vector<std::string>{"adversity_fog", "adversity_smoke",
                                                    "adversity_rain", "adversity_dim"}));
  const Planned major = Plan("major", 7);
  // four people; the forklift is left out: the room is no place for a vehicle (the default
  // world marks nothing drivable)
  EXPECT_EQ(major.agents.size(), 4u);
  for (const AgentConfig& a : major.agents) {
    EXPECT_EQ(a.kind, AgentKind::kPerson) << a.name;
    EXPECT_FALSE(a.robot_contact) << a.name;
  }
  // fog extinction from the MOR of the preset: 2.996 / 12 m
  EXPECT_NEAR(major.effects[0].Get<FogParams>().extinction.SigmaT(), -std::log(0.05) / 12.0, 1e-9);
  // smoke box inside the room (x in [-4, 4], y in [-3, 3] plus walls), floor to 2.5 m
  const BoxRegion& smoke = *major.effects[1].region;
  EXPECT_GE(smoke.min_W.x(), -4.5);
  EXPECT_LE(smoke.max_W.x(), 4.5);
  EXPECT_EQ(smoke.min_W.z(), 0.0);
  EXPECT_EQ(smoke.max_W.z(), 2.5);
}

TEST(AdversityPlan, NpcPathsAreClearOfFurnitureAndTheRobotAndDependOnTheSeed) {
  const Planned a = Plan("major", 7);
  const Planned b = Plan("major", 7);
  const Planned c = Plan("major", 8);
  ASSERT_EQ(a.agents.size(), b.agents.size());
  for (size_t i = 0; i < a.agents.size(); ++i)
    EXPECT_EQ(a.agents[i].waypoints, b.agents[i].waypoints);
  EXPECT_NE(a.agents[0].waypoints, c.agents[0].waypoints);

  // an independent check against the room's static geoms: preset NPCs are crowd agents
  // (docs/npcs.md) whose waypoints are their start and the points they walk between (people) or
  // their lane (vehicles); each is free of furniture for the agent's disc, and a person starts
  // at least 1.5 m from the robot
  WorldConfig world = LoadWorldFile(kDefaultWorld);
  ComposeOptions opts;
  const ComposedScene composed = ComposeWorld(world.models, opts);
  Simulation sim = Simulation::LoadFromString(composed.Xml());
  const FloorMap map(sim.scene(), sim.Snapshot().X_WB, 0.0, Eigen::Vector2d(-0.2, -1.45));
  ASSERT_FALSE(a.agents.empty());
  for (const AgentConfig& agent : a.agents) {
    EXPECT_EQ(agent.motion, AgentMotion::kCrowd) << agent.name;
    // the walkable grid's discs (0.3 m people, 0.7 m vehicles) less a cell of rounding
    const double radius = agent.kind == AgentKind::kPerson ? 0.2 : 0.55;
    const auto& w = agent.waypoints;
    ASSERT_FALSE(w.empty()) << agent.name;
    if (agent.kind == AgentKind::kPerson) {
      EXPECT_GE((w[0] - Eigen::Vector2d(-0.2, -1.45)).norm(), 1.5) << agent.name;
    }
    for (size_t i = 0; i < w.size(); ++i) {
      EXPECT_TRUE(map.SegmentFree(w[i], w[i], radius)) << agent.name << " waypoint " << i;
      // inside the room's interior
      EXPECT_GT(w[i].x(), -4.0);
      EXPECT_LT(w[i].x(), 4.0);
      EXPECT_GT(w[i].y(), -3.0);
      EXPECT_LT(w[i].y(), 3.0);
    }
  }
}

TEST(AdversityPlan, UnknownPresetListsTheValidNames) {
  try {
    Plan("apocalypse", 7);
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()),
              "<command line>: --adversity: unknown preset 'apocalypse'; expected one of: none, "
              "minor, major, or a preset file (FILE.yaml or FILE.yaml#NAME)");
  }
}

TEST(AdversityPlan, CliRunWithAnUnknownPresetExitsWith2AndAKnownOneRecordsIt) {
  const std::string out = penumbra::testing::ProcessTempDir() + "/adversity_cli";
  const char* bad[] = {"penumbra",  "run",     kDefaultWorld.c_str(), "--out",
                       out.c_str(), "--quiet", "--adversity",         "apocalypse"};
  EXPECT_EQ(RunCli(8, const_cast<char**>(bad)), 2);
  WorldConfig world = LoadWorldFile(kDefaultWorld);
  world.duration_sec = 0.05;
  world.cameras.at(0).width = 32;
  world.cameras.at(0).height = 24;
  RunOptions options;
  options.out_dir = out;
  options.progress = false;
  options.adversity = "major";
  RunWorld(world, options);
  const std::string text = testing::ReadAll(std::filesystem::path(out) / "run.json");
  EXPECT_NE(text.find("\"adversity\": \"major ("), std::string::npos) << text;
  EXPECT_NE(text.find("\"adversity_person0: person\""), std::string::npos);
  EXPECT_EQ(text.find("forklift"), std::string::npos);
  EXPECT_NE(text.find("\"adversity_smoke: smoke\""), std::string::npos);
}

TEST(AdversityPlan, EffectsAreEvaluatedDeterministically) {
  WorldConfig world = LoadWorldFile(kDefaultWorld);
  ComposeOptions opts;
  ComposedScene composed = ComposeWorld(world.models, opts);
  EffectsStage stage(world, &composed, "major");
  Simulation sim = Simulation::LoadFromString(composed.Xml());
  stage.Attach(&sim);
  const SceneDescription scene = stage.Bind(sim.scene());
  const WorldSnapshot snap = sim.Snapshot();
  const auto f1 = stage.Evaluate(snap, Eigen::Vector3d(0, 0, 0.4));
  ASSERT_TRUE(f1);
  EXPECT_EQ(f1->homogeneous_media.size(), 1u);  // fog
  EXPECT_EQ(f1->grid_media.size(), 1u);         // smoke
  EXPECT_EQ(f1->particles.size(), 1u);          // rain
  ASSERT_EQ(f1->light_intensity_scale.size(), scene.lights.size());
  for (float s : f1->light_intensity_scale) EXPECT_LE(s, 0.25f + 1e-6f);
  const auto f2 = stage.Evaluate(snap, Eigen::Vector3d(0, 0, 0.4));
  EXPECT_EQ(f1->particles[0].position_W, f2->particles[0].position_W);
  EXPECT_EQ(*f1->grid_media[0].density, *f2->grid_media[0].density);
}

}  // namespace
}  // namespace penumbra
