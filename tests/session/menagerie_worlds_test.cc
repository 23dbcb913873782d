// the Menagerie world files (worlds/menagerie_go1.yaml, menagerie_g1.yaml; docs/robots/
// menagerie.md) through the composer: mjlab's Go1 with mjlab's servos walks with trot_gait from
// its keyframe; mjlab's G1 holding its keyframe pose falls. Skipped when mjlab is not installed
// in the project's .venv.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "common/mjlab_assets.h"
#include "penumbra/session/session.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

const std::string kMjlabWorldRobots = testing::MjlabRobotsDir();

// runs worlds/<name>.yaml for `seconds` without a renderer; the pose of `body` at the end
Pose RunMenagerieWorld(const std::string& name, const std::string& body, double seconds,
                       Pose* start) {
  const WorldConfig world = LoadWorldFile(PENUMBRA_SOURCE_DIR "/worlds/" + name + ".yaml");
  SessionOptions options;
  options.build_renderer = false;
  Session session(world, options);
  Simulation& sim = session.sim();
  const int b = sim.scene().FindBody(body);
  EXPECT_GE(b, 0) << body;
  *start = sim.Snapshot().X_WB[b];
  while (sim.time() < seconds - 1e-9) sim.Step();
  return sim.Snapshot().X_WB[b];
}

TEST(MenagerieWorlds, Go1WalksWithTrotGait) {
  if (!std::filesystem::exists(kMjlabWorldRobots + "/unitree_go1/xmls/go1.xml"))
    GTEST_SKIP() << "mjlab 1.6.0 is not installed in " << kMjlabWorldRobots;
  Pose start;
  const Pose X = RunMenagerieWorld("menagerie_go1", "go1/trunk", 8.0, &start);
  const Eigen::Vector3d d = X.translation() - start.translation();
  std::printf(
      "[ measured ] menagerie_go1.yaml: trunk starts at z %.3f m, after 8 s dx %.3f m, dy %.3f "
      "m, z %.3f m, up-axis z %.4f\n",
      start.translation().z(), d.x(), d.y(), X.translation().z(), X.linear()(2, 2));
  EXPECT_GT(d.x(), 2.5);  // 6 s at 0.5 m/s, then trotting in place
  EXPECT_LT(d.x(), 3.3);
  EXPECT_LT(std::abs(d.y()), 0.3);
  EXPECT_GT(X.linear()(2, 2), 0.95);
}

TEST(MenagerieWorlds, G1HoldingItsKeyframeFalls) {
  if (!std::filesystem::exists(kMjlabWorldRobots + "/unitree_g1/xmls/g1.xml"))
    GTEST_SKIP() << "mjlab 1.6.0 is not installed in " << kMjlabWorldRobots;
  Pose start;
  const Pose X = RunMenagerieWorld("menagerie_g1", "g1/pelvis", 3.0, &start);
  std::printf("[ measured ] menagerie_g1.yaml: pelvis starts at z %.3f m, at 3 s z %.3f m\n",
              start.translation().z(), X.translation().z());
  EXPECT_NEAR(start.translation().z(), 0.784, 0.02);  // the key's pelvis height
  EXPECT_LT(X.translation().z(), 0.4);                // on the floor
}

}  // namespace
}  // namespace penumbra
