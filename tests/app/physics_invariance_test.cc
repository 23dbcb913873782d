// effects never feed back into physics: the default world's robot trajectory is
// bit-identical with and without fog, smoke and rain, and with an NPC that stays away;
// an NPC walking into the robot changes it only from the contact on.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "common/temp_dir.h"
#include "penumbra/run/runner.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

const std::string kDefaultWorld = std::string(PENUMBRA_SOURCE_DIR) + "/worlds/default.yaml";

// runs 2 s of the default world (small camera, to keep it fast) and returns trajectory.csv
std::vector<std::string> Trajectory(const std::string& tag,
                                    const std::vector<EffectConfig>& effects,
                                    const std::vector<AgentConfig>& agents) {
  WorldConfig world = LoadWorldFile(kDefaultWorld);
  world.duration_sec = 2.0;
  world.cameras.at(0).width = 80;
  world.cameras.at(0).height = 60;
  world.effects = effects;
  world.agents = agents;
  const fs::path out = fs::path(penumbra::testing::ProcessTempDir()) / ("invariance_" + tag);
  fs::remove_all(out);
  RunOptions options;
  options.out_dir = out.string();
  options.progress = false;
  RunWorld(world, options);
  std::ifstream f(out / "trajectory.csv");
  std::vector<std::string> rows;
  for (std::string line; std::getline(f, line);) rows.push_back(line);
  return rows;
}

std::vector<EffectConfig> Weather() {
  EffectConfig fog;
  fog.name = "fog";
  fog.params = FogParams{};
  fog.Get<FogParams>().extinction.mor_m = 15;
  EffectConfig smoke;
  smoke.name = "smoke";
  smoke.params = SmokeParams{};
  smoke.Get<SmokeParams>().density_scale_per_m = 1.5;
  smoke.region = BoxRegion{Eigen::Vector3d(-2, -2, 0), Eigen::Vector3d(2, 2, 2.5)};
  EffectConfig rain;
  rain.name = "rain";
  rain.params = RainParams{};
  rain.Get<RainParams>().rate_mm_h = 20;
  return {fog, smoke, rain};
}

AgentConfig Person(const std::string& name, Eigen::Vector2d a, Eigen::Vector2d b) {
  AgentConfig p;
  p.name = name;
  p.waypoints = {a, b};
  p.speed_m_s = 1.3;
  p.route = AgentRoute::kOnce;
  return p;
}

TEST(PhysicsInvariance, EffectsAndFarAgentsLeaveTheTrajectoryBitIdentical) {
  const std::vector<std::string> clear = Trajectory("clear", {}, {});
  ASSERT_EQ(clear.size(), 1u + 1000u);  // header + 2 s at 2 ms
  EXPECT_EQ(Trajectory("weather", Weather(), {}), clear);
  // a person walking in the far corner of the room, 3 m from the robot's path
  EXPECT_EQ(Trajectory("far_agent", {}, {Person("far", {2.5, 2.0}, {3.3, 1.2})}), clear);
}

TEST(PhysicsInvariance, AnAgentWalkingIntoTheRobotChangesItOnlyFromTheContactOn) {
  const std::vector<std::string> clear = Trajectory("clear2", {}, {});
  // a person crossing the robot's first leg head-on
  const std::vector<std::string> bumped =
      Trajectory("bumped", {}, {Person("crosser", {1.4, -1.0}, {-1.0, -1.7})});
  ASSERT_EQ(bumped.size(), clear.size());
  size_t first_diff = 0;
  while (first_diff < clear.size() && clear[first_diff] == bumped[first_diff]) ++first_diff;
  ASSERT_LT(first_diff, clear.size()) << "the agent never touched the robot";
  // rows are "step,time,...": the robot is untouched while the person is > 1 m away (t < 0.3 s)
  const double t_first = std::stod(clear[first_diff].substr(clear[first_diff].find(',') + 1));
  std::printf("trajectories identical up to step %zu (t = %.3f s), then differ\n", first_diff - 1,
              t_first);
  EXPECT_GT(t_first, 0.3);
  EXPECT_LT(t_first, 1.5);
}

}  // namespace
}  // namespace penumbra
