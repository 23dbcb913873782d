// acceptance tests of the trot_gait controller on the bundled quadruped (Go1 class,
// worlds/models/quadruped.xml): walk, stop, turn, ramp, push recovery, determinism, name
// checks and joint sign mapping. every test starts from the model's qpos0, which is its
// standing keyframe `stand`.

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "common/temp_dir.h"
#include "penumbra/config/yaml_document.h"
#include "penumbra/core/error.h"
#include "quadruped_test_util.h"

namespace penumbra {
namespace {

using namespace quadruped_test;

// 20 N s lateral push: 200 N along the trunk's y axis for 0.1 s
constexpr double kPushForceN = 200;
constexpr double kPushDurationSec = 0.1;

std::string Config(const std::string& commands, const std::string& legs = LegsYaml()) {
  return "base_body: trunk\n" + legs + "commands: " + commands + "\n";
}

TEST(QuadrupedTrot, ModelGeometryAndMassAreReadFromTheModel) {
  Rig rig = MakeRig("quadruped", Ground::kFlat, Config("[]"));
  EXPECT_NEAR(rig.gait->mass_kg(), 12.316, 1e-9);
  const auto& g = rig.gait->leg_geometry();
  const auto& hips = rig.gait->hip_offsets();
  for (int i = 0; i < 4; ++i) {
    const double side = (i == 0 || i == 2) ? -1 : 1;  // FR, RR right; FL, RL left
    const double front = i < 2 ? 1 : -1;
    EXPECT_NEAR(g[i].abduction_m, side * 0.08, 1e-12) << i;
    EXPECT_NEAR(g[i].thigh_m, 0.213, 1e-12) << i;
    EXPECT_NEAR(g[i].calf_m, 0.213, 1e-12) << i;
    EXPECT_NEAR(hips[i].x(), front * 0.1881, 1e-12) << i;
    EXPECT_NEAR(hips[i].y(), side * 0.04675, 1e-12) << i;
    EXPECT_NEAR(hips[i].z(), 0, 1e-12) << i;
  }
  rig.sim.Step();
  // target height: COM above the plane of the foot centres in the standing pose
  EXPECT_GT(rig.gait->body_height_m(), 0.23);
  EXPECT_LT(rig.gait->body_height_m(), 0.265);  // below the trunk origin (0.265 above them)
}

// the controller's analytic leg model (FK, Jacobian used for the stance torques) agrees with
// MuJoCo's kinematics of the bundled model while it walks and turns.
TEST(QuadrupedTrot, LegModelMatchesMujocoKinematics) {
  for (const char* robot : {"quadruped", "quadruped_arm"}) {
    Rig rig = MakeRig(robot, Ground::kFlat, Config("[{t: 0, vx: 0.4, vy: 0.1, yaw_rate: 0.4}]"));
    auto check = std::make_unique<LegModelCheck>(rig.gait);
    LegModelCheck* c = check.get();
    rig.sim.AddController(std::move(check));
    RunUntil(&rig, 1.0);
    EXPECT_EQ(c->checks, 500);
    EXPECT_LT(c->max_position_error_m, 1e-12) << robot;
    EXPECT_LT(c->max_jacobian_error, 1e-12) << robot;
  }
}

// acceptance: from standing, 0.5 m/s forward for 6 s travels 3.0 +- 0.3 m with lateral
// drift < 0.3 m and the trunk never touching the ground; then it stops.
TEST(QuadrupedTrot, WalksForwardThreeMetresInSixSecondsAndStops) {
  Rig rig = MakeRig("quadruped", Ground::kFlat, Config("[{t: 0, vx: 0.5}, {t: 6, vx: 0}]"));
  const Eigen::Vector3d p0 = Trunk(rig).translation();
  RunUntil(&rig, 6.0);
  const Pose X6 = Trunk(rig);
  const Eigen::Vector3d d = X6.translation() - p0;
  std::printf("[ measured ] forward walk: dx = %.3f m, dy = %.4f m in 6 s, yaw %.2f deg\n", d.x(),
              d.y(), Yaw(X6) * 180 / M_PI);
  EXPECT_NEAR(d.x(), 3.0, 0.3);
  EXPECT_LT(std::abs(d.y()), 0.3);
  // stop: with a zero command the robot trots in place; 1 s after the command, it moves
  // less than 2.5 cm over the next 0.5 s
  RunUntil(&rig, 7.0);
  const Eigen::Vector3d p7 = Trunk(rig).translation();
  RunUntil(&rig, 7.5);
  const Eigen::Vector3d p75 = Trunk(rig).translation();
  std::printf("[ measured ] after stopping: %.4f m in 0.5 s\n", (p75 - p7).head<2>().norm());
  EXPECT_LT((p75 - p7).head<2>().norm(), 0.025);
  EXPECT_EQ(rig.probe->max_trunk_touch_n, 0.0)
      << "trunk touched at t = " << rig.probe->first_trunk_touch_sec;
  EXPECT_GT(rig.probe->min_up_z, 0.95);
}

// acceptance: turn 90 deg in place within 10 deg.
TEST(QuadrupedTrot, TurnsNinetyDegreesInPlace) {
  Rig rig = MakeRig("quadruped", Ground::kFlat,
                    Config("[{t: 0, yaw_rate: 0.7853981634}, {t: 2, yaw_rate: 0}]"));
  const Eigen::Vector3d p0 = Trunk(rig).translation();
  RunUntil(&rig, 4.0);
  const Pose X = Trunk(rig);
  const double yaw_deg = Yaw(X) * 180 / M_PI;
  const double drift = (X.translation() - p0).head<2>().norm();
  std::printf("[ measured ] turn in place: yaw %.2f deg, drift %.3f m\n", yaw_deg, drift);
  EXPECT_NEAR(yaw_deg, 90, 10);
  EXPECT_LT(drift, 0.15);
  EXPECT_EQ(rig.probe->max_trunk_touch_n, 0.0);
}

// acceptance: climbs the 10 deg ramp of worlds/models/ramp.xml (foot at x = 1.5 m, top at
// x = 3.5 m, 0.3527 m high) and walks onto the platform with all four feet.
TEST(QuadrupedTrot, ClimbsTheTenDegreeRamp) {
  Rig rig = MakeRig("quadruped", Ground::kRamp, Config("[{t: 0, vx: 0.5}, {t: 9.5, vx: 0}]"));
  RunUntil(&rig, 10.5);
  WorldSnapshot snap;
  rig.sim.Snapshot(&snap);
  const Pose& X = snap.X_WB[rig.trunk];
  const double top = 2.0 * std::tan(10 * M_PI / 180);
  double min_foot_x = 1e9, min_foot_z = 1e9;
  for (const char* leg : {"FR_calf", "FL_calf", "RR_calf", "RL_calf"}) {
    const Eigen::Vector3d foot =
        snap.X_WB[rig.sim.scene().FindBody(leg)] * Eigen::Vector3d(0, 0, -0.213);
    min_foot_x = std::min(min_foot_x, foot.x());
    min_foot_z = std::min(min_foot_z, foot.z());
  }
  std::printf(
      "[ measured ] ramp: trunk at x = %.3f, z = %.3f; rearmost foot x = %.3f, lowest "
      "foot centre z = %.3f (platform top %.4f)\n",
      X.translation().x(), X.translation().z(), min_foot_x, min_foot_z, top);
  EXPECT_GT(min_foot_x, 3.5 + 0.05);          // every foot past the top edge
  EXPECT_NEAR(min_foot_z, top + 0.02, 0.01);  // standing on the platform
  EXPECT_GT(X.translation().z(), top + 0.2);
  EXPECT_EQ(rig.probe->max_trunk_touch_n, 0.0)
      << "trunk touched at t = " << rig.probe->first_trunk_touch_sec;
  EXPECT_GT(rig.probe->min_up_z, 0.9);
}

// acceptance: survives a 20 N s lateral push while walking at 0.5 m/s, and walks on.
TEST(QuadrupedTrot, SurvivesTwentyNewtonSecondLateralPush) {
  Rig rig = MakeRig("quadruped", Ground::kFlat, Config("[{t: 0, vx: 0.5}]"));
  RunUntil(&rig, 2.0);
  double impulse = 0;
  double max_vy = 0;
  while (rig.sim.time() < 5.0 - 1e-9) {
    const double t = rig.sim.time();
    const bool pushing = t >= 2.0 - 1e-9 && t < 2.0 + kPushDurationSec - 1e-9;
    rig.sim.ctrl()[rig.push] = pushing ? kPushForceN : 0.0;
    if (pushing) impulse += kPushForceN * rig.sim.timestep();
    rig.sim.Step();
    max_vy = std::max(max_vy, rig.sim.qvel()[1]);
  }
  EXPECT_NEAR(impulse, 20.0, 1e-9);
  const Pose X = Trunk(rig);
  const auto qvel = rig.sim.qvel();
  std::printf(
      "[ measured ] push: peak lateral speed %.2f m/s, min up z %.3f, at 5 s v = (%.2f, "
      "%.2f) m/s, yaw %.1f deg, y = %.3f m\n",
      max_vy, rig.probe->min_up_z, qvel[0], qvel[1], Yaw(X) * 180 / M_PI, X.translation().y());
  EXPECT_GT(max_vy, 0.5);  // the push did move the robot
  EXPECT_EQ(rig.probe->max_trunk_touch_n, 0.0)
      << "trunk touched at t = " << rig.probe->first_trunk_touch_sec;
  EXPECT_GT(rig.probe->min_up_z, 0.5);  // never tipped past 60 deg
  // recovered: walking straight at the commanded speed again (a trot's speed oscillates
  // within a stride, hence the bands)
  EXPECT_NEAR(qvel[0], 0.5, 0.15);
  EXPECT_LT(std::abs(qvel[1]), 0.15);
  EXPECT_LT(std::abs(Yaw(X)), 10 * M_PI / 180);
}

// the programmatic command source (for the middleware) overrides the script until cleared.
TEST(QuadrupedTrot, SetCommandOverridesTheScript) {
  Rig rig = MakeRig("quadruped", Ground::kFlat, Config("[{t: 0, vx: 0}]"));
  const Eigen::Vector3d p0 = Trunk(rig).translation();
  RunUntil(&rig, 0.5);
  rig.gait->SetTwist({0.0, -0.3, 0.0});  // sideways to the right
  RunUntil(&rig, 3.5);
  EXPECT_EQ(rig.gait->command().vy, -0.3);
  const Eigen::Vector3d p1 = Trunk(rig).translation();
  std::printf("[ measured ] SetCommand vy = -0.3 m/s for 3 s: dy = %.3f m, dx = %.3f m\n",
              p1.y() - p0.y(), p1.x() - p0.x());
  EXPECT_NEAR(p1.y() - p0.y(), -0.9, 0.15);
  EXPECT_LT(std::abs(p1.x() - p0.x()), 0.1);
  rig.gait->ClearTwist();  // back to the script: stand (trot in place)
  RunUntil(&rig, 4.5);
  EXPECT_EQ(rig.gait->command().vy, 0.0);
  const Eigen::Vector3d p2 = Trunk(rig).translation();
  RunUntil(&rig, 5.0);
  EXPECT_LT((Trunk(rig).translation() - p2).head<2>().norm(), 0.025);
  EXPECT_EQ(rig.probe->max_trunk_touch_n, 0.0);
}

// two runs of the same world are bit-identical at every step.
TEST(QuadrupedTrot, TwoRunsAreBitIdentical) {
  const std::string cfg = Config("[{t: 0, vx: 0.4, vy: 0.1, yaw_rate: 0.3}, {t: 1.5, vx: -0.2}]");
  Rig a = MakeRig("quadruped", Ground::kFlat, cfg);
  Rig b = MakeRig("quadruped", Ground::kFlat, cfg);
  ASSERT_TRUE(StepInLockstep(a.sim, b.sim, 1250));
  // and it did move
  EXPECT_GT(std::abs(a.sim.qpos()[0]) + std::abs(a.sim.qpos()[1]), 0.2);
}

TEST(QuadrupedTrot, MissingNamesFailAtLoadListingAll) {
  std::string legs = LegsYaml();
  legs.replace(legs.find("FR_calf,"), 8, "FR_knee,");
  legs.replace(legs.find("RL_foot,"), 8, "RL_toe,");
  Simulation sim =
      Simulation::LoadFromString(SceneXml("quadruped", Ground::kFlat), std::nullopt, kModelsDir);
  ControllerConfig cfg{"trot_gait", ParseYaml("base_body: body\n" + legs), 7};
  try {
    sim.AddController(MakeController(cfg, "", "world.yaml"));
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    std::printf("%s\n", e.what());
    const std::string m = e.what();
    EXPECT_NE(m.find("world.yaml:7"), std::string::npos) << m;
    EXPECT_NE(m.find("4 names not found"), std::string::npos) << m;
    EXPECT_NE(m.find("base_body: body 'body'"), std::string::npos) << m;
    EXPECT_NE(m.find("legs.FR.calf: joint 'FR_knee'"), std::string::npos) << m;
    EXPECT_NE(m.find("legs.FR.actuators[2]: actuator 'FR_knee'"), std::string::npos) << m;
    EXPECT_NE(m.find("legs.RL.foot: site 'RL_toe'"), std::string::npos) << m;
  } catch (const std::exception& e) {
    FAIL() << "expected a ConfigError, got: " << e.what();
  }
}

// "any 12-DoF quadruped whose joints are mapped": the same robot with its knee axes
// reversed (axis -y, angles negated) walks the same with signs [1, 1, -1].
TEST(QuadrupedTrot, JointSignsMapReversedAxes) {
  std::ifstream f(kModelsDir + "/quadruped.xml");
  std::stringstream ss;
  ss << f.rdbuf();
  std::string xml = ss.str();
  auto replace_all = [&](const std::string& from, const std::string& to) {
    int n = 0;
    for (size_t p = xml.find(from); p != std::string::npos; p = xml.find(from, p + to.size())) {
      xml.replace(p, from.size(), to);
      ++n;
    }
    return n;
  };
  ASSERT_EQ(
      replace_all(R"(axis="0 1 0" range="-2.818 -0.888")", R"(axis="0 -1 0" range="0.888 2.818")"),
      1);
  ASSERT_EQ(replace_all(R"(ref="-1.8")", R"(ref="1.8")"), 4);
  ASSERT_EQ(replace_all(R"(qpos="0 0 0.285 1 0 0 0 0 0.9 -1.8 0 0.9 -1.8 0 0.9 -1.8 0 0.9 -1.8")",
                        R"(qpos="0 0 0.285 1 0 0 0 0 0.9 1.8 0 0.9 1.8 0 0.9 1.8 0 0.9 1.8")"),
            1);
  // the model has no asset files, so it loads from a scratch folder
  const std::string dir = penumbra::testing::ProcessTempDir();
  {
    std::ofstream out(dir + "/quadruped_reversed_knees.xml");
    out << xml;
  }
  const std::string scene = SceneXml("quadruped_reversed_knees", Ground::kFlat);
  std::string legs = LegsYaml();
  ASSERT_EQ(std::count(legs.begin(), legs.end(), '['), 4);
  for (size_t p = legs.find("signs: [1, 1, 1]"); p != std::string::npos;
       p = legs.find("signs: [1, 1, 1]", p))
    legs.replace(p, 16, "signs: [1, 1, -1]");

  auto walk = [&](const std::string& model_xml, const std::string& asset_dir,
                  const std::string& legs_yaml) {
    Rig rig{Simulation::LoadFromString(model_xml, std::nullopt, asset_dir)};
    ControllerConfig cfg{"trot_gait", ParseYaml(Config("[{t: 0, vx: 0.5}]", legs_yaml)), 1};
    rig.sim.AddController(MakeController(cfg, "", "test.yaml"));
    rig.trunk = rig.sim.scene().FindBody("trunk");
    const double x0 = Trunk(rig).translation().x();
    RunUntil(&rig, 2.0);
    return Trunk(rig).translation().x() - x0;
  };
  const double reference = walk(SceneXml("quadruped", Ground::kFlat), kModelsDir, LegsYaml());
  const double reversed = walk(scene, dir, legs);
  std::printf(
      "[ measured ] 2 s at 0.5 m/s: %.4f m (model), %.4f m (reversed knees), difference %.2e m\n",
      reference, reversed, reversed - reference);
  EXPECT_GT(reference, 0.75);
  // identical dynamics up to the sign convention: the trajectories agree to rounding
  EXPECT_NEAR(reversed, reference, 1e-6);
}

}  // namespace
}  // namespace penumbra
