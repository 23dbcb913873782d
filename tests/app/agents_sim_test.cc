// NPC agents in the physics: mocap bodies driven along their paths (one-way coupling).
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "common/temp_dir.h"
#include "penumbra/compose/agent_bodies.h"
#include "penumbra/session/world_composer.h"
#include "penumbra/core/error.h"
#include "penumbra/physics/simulation.h"
#include "penumbra/session/effects_stage.h"

namespace penumbra {
namespace {

// a floor, a wall segment far away (static bounds) and a free 0.3 m box of 2 kg at x = 2
const char* kArena = R"(<mujoco model="arena">
  <option timestep="0.002"/>
  <worldbody>
    <geom name="floor" type="plane" size="10 10 0.1"/>
    <geom name="wall_n" type="box" pos="0 6 1" size="6 0.1 1"/>
    <geom name="wall_s" type="box" pos="0 -6 1" size="6 0.1 1"/>
    <body name="crate" pos="2 0 0.15">
      <freejoint name="crate_free"/>
      <geom name="crate" type="box" size="0.15 0.15 0.15" mass="2" friction="0.5"/>
    </body>
  </worldbody>
</mujoco>)";

std::string ArenaFile() {
  const auto dir = std::filesystem::path(penumbra::testing::ProcessTempDir());
  std::filesystem::create_directories(dir);
  const auto path = dir / "arena.xml";
  std::ofstream(path) << kArena;
  return path.string();
}

struct SimRun {
  std::vector<std::vector<double>> qpos;  // per step
  std::vector<Pose> X_W_agent;            // per step
  std::vector<double> time;
};

SimRun Simulate(const std::vector<AgentConfig>& agents, double seconds) {
  WorldConfig world;
  ModelConfig m;
  m.name = "arena";
  m.file = ArenaFile();
  world.models.push_back(m);
  world.agents = agents;
  ComposeOptions opts;
  ComposedScene composed = ComposeWorld(world.models, opts);
  EffectsStage stage(world, &composed);
  Simulation sim = Simulation::LoadFromString(composed.Xml());
  stage.Attach(&sim);
  const int body = agents.empty() ? -1 : sim.scene().FindBody(AgentBodyName(agents[0].name));
  SimRun run;
  while (sim.time() < seconds - 1e-9) {
    sim.Step();
    run.qpos.emplace_back(sim.qpos().begin(), sim.qpos().end());
    run.time.push_back(sim.time());
    if (body >= 0) run.X_W_agent.push_back(sim.Snapshot().X_WB[body]);
  }
  return run;
}

AgentConfig Walker() {
  AgentConfig a;
  a.name = "walker";
  a.waypoints = {{0, 0}, {4, 0}};
  a.speed_m_s = 1.0;
  a.pause_sec = 0.5;
  a.route = AgentRoute::kPingPong;
  a.height_m = 1.75;
  a.height_given = true;
  return a;
}

TEST(AgentsInPhysics, TheAgentFollowsItsPathWhateverItTouches) {
  const AgentConfig a = Walker();
  const AgentPath path(a);
  const SimRun run = Simulate({a}, 5.0);
  double worst_pos = 0, worst_rot = 0, lowest = 0;
  for (size_t k = 0; k < run.time.size(); ++k) {
    const Pose expected = path.X_WA(run.time[k]);
    // the root (pelvis) bobs down with the walking cycle (effects/walker_gait.h); its floor
    // position and heading are the path's
    const Eigen::Vector3d d = run.X_W_agent[k].translation() - expected.translation();
    worst_pos = std::max(worst_pos, d.head<2>().norm());
    lowest = std::min(lowest, d.z());
    worst_rot = std::max(worst_rot, (run.X_W_agent[k].linear() - expected.linear()).norm());
  }
  EXPECT_LE(lowest, 0);
  EXPECT_GT(lowest, -0.06) << "the pelvis drops at most l (1 - cos theta_max)";
  std::printf("agent pose vs path over %zu steps: max position error %.3g m, rotation %.3g\n",
              run.time.size(), worst_pos, worst_rot);
  // the pose at every step is the path's pose at that step's sim time (1 mm / 1e-9 tolerance)
  EXPECT_LT(worst_pos, 1e-3) << worst_pos;
  EXPECT_LT(worst_rot, 1e-9) << worst_rot;
  // it walked 4 m out, paused 0.5 s, and is 0.5 m on the way back at t = 5 s
  EXPECT_NEAR(run.X_W_agent.back().translation().x(), 3.5, 1e-3);
}

TEST(AgentsInPhysics, AWalkingPersonPushesAFreeBox) {
  const SimRun with = Simulate({Walker()}, 4.0);
  const SimRun without = Simulate({}, 4.0);
  // crate qpos: x, y, z, qw, qx, qy, qz
  const double x_with = with.qpos.back()[0];
  const double x_without = without.qpos.back()[0];
  std::printf("crate x after 4 s: %.4f m with the agent, %.4f m without (y %.4f, z %.4f)\n", x_with,
              x_without, with.qpos.back()[1], with.qpos.back()[2]);
  EXPECT_NEAR(x_without, 2.0, 1e-3) << "the crate rests without the agent";
  // the person's swinging legs (shins r 0.0525 m, feet 6.8 cm high) kick the 0.3 m crate
  // ahead and aside out of its path: it must have moved by more than 0.5 m, forward, and still
  // stand on the floor (measured: 0.94 m forward, 0.37 m aside)
  const double moved = std::hypot(x_with - 2.0, with.qpos.back()[1]);
  EXPECT_GT(moved, 0.5) << "crate x " << x_with;
  EXPECT_GT(x_with, 2.5);
  EXPECT_NEAR(with.qpos.back()[2], 0.15, 0.01) << "on the floor";
}

TEST(AgentsInPhysics, RunsAreBitIdentical) {
  const SimRun a = Simulate({Walker()}, 3.0);
  const SimRun b = Simulate({Walker()}, 3.0);
  ASSERT_EQ(a.qpos.size(), b.qpos.size());
  for (size_t k = 0; k < a.qpos.size(); ++k) ASSERT_EQ(a.qpos[k], b.qpos[k]) << "step " << k;
}

TEST(AgentsInPhysics, AgentBodiesAreMocapWithCollidingGeomsAndSemanticClass) {
  WorldConfig world;
  ModelConfig m;
  m.name = "arena";
  m.file = ArenaFile();
  world.models.push_back(m);
  AgentConfig lift = Walker();
  lift.name = "lift";
  lift.kind = AgentKind::kForklift;
  world.agents = {Walker(), lift};
  ComposedScene composed = ComposeWorld(world.models, ComposeOptions{});
  EffectsStage stage(world, &composed);
  Simulation sim = Simulation::LoadFromString(composed.Xml());
  const SceneDescription scene = stage.Bind(sim.scene());
  const int person = scene.FindBody("agents/walker");
  const int forklift = scene.FindBody("agents/lift");
  ASSERT_GE(person, 0);
  ASSERT_GE(forklift, 0);
  int person_geoms = 0, lift_geoms = 0;
  double top = 0;
  for (const Geom& g : scene.geoms) {
    if (g.body > 0 && IsAgentBodyOf(scene.bodies[g.body].name, "walker")) {
      ++person_geoms;
      EXPECT_EQ(g.semantic_class, kSemanticClassPerson) << g.name;
      if (g.shape == GeomShape::kSphere) top = std::max(top, g.X_BG.translation().z() + g.size[0]);
    }
    if (g.body > 0 && IsAgentBodyOf(scene.bodies[g.body].name, "lift")) {
      ++lift_geoms;
      EXPECT_EQ(g.semantic_class, kSemanticClassVehicle) << g.name;
    }
  }
  EXPECT_GE(person_geoms, 14);  // root: pelvis, torso, neck, head; limbs: 10 geoms
  EXPECT_GE(lift_geoms, 20);    // body: 13 geoms; wheels: tyre and hub each
  EXPECT_NEAR(top, 1.75, 1e-9) << "head top of a 1.75 m person";
  EXPECT_THROW(sim.AddMocapDriver("arena/crate", [](double) { return Pose::Identity(); }),
               ConfigError);
  EXPECT_THROW(sim.AddMocapDriver("nobody", [](double) { return Pose::Identity(); }), ConfigError);
}

TEST(AgentsInPhysics, AWaypointOutsideTheWorldIsAConfigError) {
  WorldConfig world;
  world.file = "w.yaml";
  ModelConfig m;
  m.name = "arena";
  m.file = ArenaFile();
  world.models.push_back(m);
  AgentConfig a = Walker();
  a.waypoints[1] = Eigen::Vector2d(40, 0);
  world.agents = {a};
  ComposedScene composed = ComposeWorld(world.models, ComposeOptions{});
  EffectsStage stage(world, &composed);
  Simulation sim = Simulation::LoadFromString(composed.Xml());
  try {
    stage.Attach(&sim);  // checked against the compiled model's static geometry
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "agents[0].waypoints[1]");
    EXPECT_NE(std::string(e.what()).find("lies outside the world; expected x in [-7, 7]"),
              std::string::npos)
        << e.what();
  }
}

TEST(AgentsInPhysics, KeyframesWithMocapPosesAreExtendedByTheAgents) {
  const auto dir = std::filesystem::path(penumbra::testing::ProcessTempDir());
  std::filesystem::create_directories(dir);
  const auto path = dir / "target.xml";
  std::ofstream(path) << R"(<mujoco model="target">
  <worldbody>
    <body name="target" mocap="true" pos="1 0 1"><geom type="sphere" size="0.1"/></body>
  </worldbody>
  <keyframe><key name="up" mpos="1 0 2" mquat="1 0 0 0"/></keyframe>
</mujoco>)";
  ModelConfig m;
  m.name = "t";
  m.file = path.string();
  ComposedScene composed = ComposeWorld({m}, ComposeOptions{});
  AgentConfig a = Walker();
  a.waypoints = {{3, 1}, {4, 1}};
  AddAgentBodies(AgentBodySpecs({a}, 0), "", &composed);
  // the target's pose, then the person's root and its 8 limbs at their standing poses
  EXPECT_NE(composed.Xml().find("mpos=\"1 0 2 3 1 0 "), std::string::npos) << composed.Xml();
  Simulation loaded = Simulation::LoadFromString(composed.Xml());
  EXPECT_EQ(loaded.MocapBodyNames().size(), 1u + 1u + 8u);
  Simulation sim = Simulation::LoadFromString(composed.Xml());
  EXPECT_EQ(sim.model_info().keys.size(), 1u);
}

}  // namespace
}  // namespace penumbra
