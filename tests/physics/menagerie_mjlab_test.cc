// Menagerie's Unitree Go1 and G1 as mjlab 1.6.0 vendors them (its MJCF and meshes, unchanged),
// with the actuators and keyframes mjlab configures in Python written as MJCF
// (worlds/models/menagerie/unitree_go1.xml, unitree_g1.xml attach mjlab's files from the
// project's .venv), on a flat floor through MuJoCo's own loader: the Go1 stands on its
// position servos from its keyframe and trot_gait walks it; the G1 holding its keyframe pose
// with mjlab's gains (no balance controller) tips over, as measured and documented in
// docs/robots/menagerie.md. Skipped when mjlab is not installed in the .venv.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "common/mjlab_assets.h"
#include "penumbra/config/yaml_document.h"
#include "penumbra/control/controller_factory.h"
#include "penumbra/physics/simulation.h"

namespace penumbra {
namespace {

const std::string kWrappers = PENUMBRA_SOURCE_DIR "/worlds/models/menagerie";
const std::string kMjlabRobots = testing::MjlabRobotsDir();

bool MjlabRobotInstalled(const std::string& robot_xml) {
  return !kMjlabRobots.empty() && std::filesystem::exists(kMjlabRobots + "/" + robot_xml);
}

// the wrapper `file` with a floor added to its world body, loaded with its keyframe "home".
Simulation LoadMjlabOnFloor(const std::string& file) {
  std::ifstream f(kWrappers + "/" + file);
  std::stringstream ss;
  ss << f.rdbuf();
  std::string xml = ss.str();
  const size_t body = xml.find("<worldbody>");
  EXPECT_NE(body, std::string::npos);
  xml.insert(body + 11, "\n    <geom name=\"floor\" type=\"plane\" size=\"0 0 0.05\"/>");
  Simulation sim = Simulation::LoadFromString(xml, std::nullopt, kWrappers);
  sim.ApplyKeyframe("home", "", "home");
  return sim;
}

Pose MjlabBodyPose(const Simulation& sim, int body) {
  WorldSnapshot snap;
  sim.Snapshot(&snap);
  return snap.X_WB[body];
}

TEST(MenagerieMjlab, Go1StandsOnItsServosFromItsKeyframe) {
  if (!MjlabRobotInstalled("unitree_go1/xmls/go1.xml"))
    GTEST_SKIP() << "mjlab 1.6.0 is not installed in " << kMjlabRobots
                 << " (scripts/install-deps.sh installs it)";
  Simulation sim = LoadMjlabOnFloor("unitree_go1.xml");
  const int trunk = sim.scene().FindBody("trunk");
  ASSERT_GE(trunk, 0);
  EXPECT_NEAR(MjlabBodyPose(sim, trunk).translation().z(), 0.278, 1e-9);  // mjlab's INIT_STATE
  double min_z = 1e9, max_z = 0, min_up = 1;
  while (sim.time() < 5.0 - 1e-9) {
    sim.Step();
    const Pose X = MjlabBodyPose(sim, trunk);
    min_z = std::min(min_z, X.translation().z());
    max_z = std::max(max_z, X.translation().z());
    min_up = std::min(min_up, X.linear()(2, 2));
  }
  const Pose X = MjlabBodyPose(sim, trunk);
  std::printf(
      "[ measured ] Go1 (mjlab) holding its key for 5 s: trunk z in [%.3f, %.3f] m, ends at "
      "%.3f m, up-axis z >= %.4f (tilt <= %.1f deg), moved %.3f m\n",
      min_z, max_z, X.translation().z(), min_up, std::acos(min_up) * 180 / M_PI,
      X.translation().head<2>().norm());
  // mjlab's servos are soft (kp 15.9 / 35.8 N m/rad): the trunk settles about 5 cm lower,
  // pitched about 10 deg, and stays there
  EXPECT_GT(min_z, 0.20);
  EXPECT_LT(max_z, 0.28);
  EXPECT_GT(min_up, 0.97);
  EXPECT_LT(X.translation().head<2>().norm(), 0.2);
}

TEST(MenagerieMjlab, TrotGaitWalksTheGo1OnItsPositionServos) {
  if (!MjlabRobotInstalled("unitree_go1/xmls/go1.xml"))
    GTEST_SKIP() << "mjlab 1.6.0 is not installed in " << kMjlabRobots
                 << " (scripts/install-deps.sh installs it)";
  Simulation sim = LoadMjlabOnFloor("unitree_go1.xml");
  std::string config = "base_body: trunk\nlegs:\n";
  for (const char* leg : {"FR", "FL", "RR", "RL"}) {
    const std::string l = leg;
    config += "  " + l + ": {hip: " + l + "_hip_joint, thigh: " + l + "_thigh_joint, calf: " + l +
              "_calf_joint, foot: " + l + "}\n";
  }
  config += "commands: [{t: 0, vx: 0.5}, {t: 6, vx: 0}]\n";
  sim.AddController(MakeController({"trot_gait", ParseYaml(config), 1}, "", "test.yaml"));
  const int trunk = sim.scene().FindBody("trunk");
  const Eigen::Vector3d p0 = MjlabBodyPose(sim, trunk).translation();
  double min_up = 1;
  while (sim.time() < 7.0 - 1e-9) {
    sim.Step();
    min_up = std::min(min_up, MjlabBodyPose(sim, trunk).linear()(2, 2));
  }
  const Pose X = MjlabBodyPose(sim, trunk);
  const Eigen::Vector3d d = X.translation() - p0;
  std::printf(
      "[ measured ] Go1 (mjlab) trot_gait 0.5 m/s for 6 s: dx = %.3f m, dy = %.3f m, trunk z "
      "%.3f m, up-axis z >= %.4f\n",
      d.x(), d.y(), X.translation().z(), min_up);
  EXPECT_GT(d.x(), 2.0);
  EXPECT_LT(d.x(), 3.3);
  EXPECT_LT(std::abs(d.y()), 0.3);
  EXPECT_GT(min_up, 0.9);
}

TEST(MenagerieMjlab, G1HoldingItsKeyframePoseWithMjlabGainsTipsOver) {
  if (!MjlabRobotInstalled("unitree_g1/xmls/g1.xml"))
    GTEST_SKIP() << "mjlab 1.6.0 is not installed in " << kMjlabRobots
                 << " (scripts/install-deps.sh installs it)";
  Simulation sim = LoadMjlabOnFloor("unitree_g1.xml");
  const int pelvis = sim.scene().FindBody("pelvis");
  ASSERT_GE(pelvis, 0);
  double tipped_at = -1;
  double z_at_half = 0;
  while (sim.time() < 2.0 - 1e-9) {
    sim.Step();
    const Pose X = MjlabBodyPose(sim, pelvis);
    if (std::abs(sim.time() - 0.5) < 1e-9) z_at_half = X.translation().z();
    if (tipped_at < 0 && X.linear()(2, 2) < std::cos(30 * M_PI / 180)) tipped_at = sim.time();
  }
  const Pose X = MjlabBodyPose(sim, pelvis);
  std::printf(
      "[ measured ] G1 (mjlab) holding its key: pelvis z %.3f m at 0.5 s, tilted past 30 deg "
      "at %.2f s, pelvis z %.3f m at 2 s\n",
      z_at_half, tipped_at, X.translation().z());
  // it stands for the first half second (the key's feet are on the floor) ...
  EXPECT_GT(z_at_half, 0.7);
  // ... and then falls: a fixed pose on soft servos does not balance a humanoid
  EXPECT_GT(tipped_at, 0.5);
  EXPECT_LT(X.translation().z(), 0.4);
}

}  // namespace
}  // namespace penumbra
