// acceptance tests of the trot_gait controller on the bundled quadruped_arm (B1 class with
// a Z1-class arm, worlds/models/quadruped_arm.xml): walking at 0.4 m/s with the arm held
// in a raised pose, turning, the ramp, push recovery and determinism.

#include <gtest/gtest.h>

#include "quadruped_test_util.h"

namespace penumbra {
namespace {

using namespace quadruped_test;

// the arm's held pose: upper arm raised, forearm forward, gripper half open
const std::vector<std::pair<std::string, double>> kArmPose = {
    {"arm_joint1", 0.0}, {"arm_joint2", 1.2}, {"arm_joint3", -1.0}, {"arm_joint4", -0.2},
    {"arm_joint5", 0.0}, {"arm_joint6", 0.0}, {"gripper", 0.02}};

std::string Config(const std::string& commands) {
  std::string hold = "hold: {";
  for (size_t i = 0; i < kArmPose.size(); ++i)
    hold += (i ? ", " : "") + kArmPose[i].first + ": " + std::to_string(kArmPose[i].second);
  hold += "}\n";
  // the heavier legs get stiffer swing servos and a higher swing
  return "base_body: trunk\n" + LegsYaml() + "commands: " + commands +
         "\nswing_kp: 200\nswing_kd: 4\nswing_height_m: 0.1\n" + hold;
}

// largest deviation (rad) of the arm joints from the held pose from `t_from` until `t_to`
double RunTracking(Rig* rig, double t_from, double t_to) {
  std::vector<int> adr;
  for (const auto& [name, v] : kArmPose)
    if (name != "gripper")
      adr.push_back(rig->sim.model_info()
                        .joints[rig->sim.model_info().Find(ModelObject::kJoint, name)]
                        .qpos_adr);
  double worst = 0;
  while (rig->sim.time() < t_to - 1e-9) {
    rig->sim.Step();
    if (rig->sim.time() < t_from) continue;
    for (size_t k = 0; k < adr.size(); ++k)
      worst = std::max(worst, std::abs(rig->sim.qpos()[adr[k]] - kArmPose[k].second));
  }
  return worst;
}

TEST(QuadrupedArmTrot, MassIsReadFromTheModel) {
  Rig rig = MakeRig("quadruped_arm", Ground::kFlat, Config("[]"));
  EXPECT_NEAR(rig.gait->mass_kg(), 55.01, 1e-9);
  for (const auto& g : rig.gait->leg_geometry()) {
    EXPECT_NEAR(std::abs(g.abduction_m), 0.12675, 1e-12);
    EXPECT_NEAR(g.thigh_m, 0.35, 1e-12);
    EXPECT_NEAR(g.calf_m, 0.35, 1e-12);
  }
}

// acceptance: 0.4 m/s for 6 s travels 2.4 +- 0.24 m (10 %), lateral drift < 0.3 m, the trunk
// never touches the ground, and the arm holds its pose within 0.05 rad.
TEST(QuadrupedArmTrot, WalksForwardHoldingTheArm) {
  Rig rig = MakeRig("quadruped_arm", Ground::kFlat, Config("[{t: 0, vx: 0.4}, {t: 6, vx: 0}]"));
  const Eigen::Vector3d p0 = Trunk(rig).translation();
  // the arm moves from its folded qpos0 to the held pose during the first second
  const double arm_error = RunTracking(&rig, 1.0, 6.0);
  const Eigen::Vector3d d = Trunk(rig).translation() - p0;
  std::printf(
      "[ measured ] quadruped_arm walk: dx = %.3f m, dy = %.4f m in 6 s, arm error "
      "<= %.4f rad\n",
      d.x(), d.y(), arm_error);
  EXPECT_NEAR(d.x(), 2.4, 0.24);
  EXPECT_LT(std::abs(d.y()), 0.3);
  EXPECT_LT(arm_error, 0.05);
  RunTracking(&rig, 6.0, 7.0);
  const Eigen::Vector3d p7 = Trunk(rig).translation();
  RunTracking(&rig, 7.0, 7.5);
  EXPECT_LT((Trunk(rig).translation() - p7).head<2>().norm(), 0.025);  // stopped
  EXPECT_EQ(rig.probe->max_trunk_touch_n, 0.0);
  EXPECT_GT(rig.probe->min_up_z, 0.95);
}

TEST(QuadrupedArmTrot, TurnsNinetyDegreesInPlace) {
  Rig rig = MakeRig("quadruped_arm", Ground::kFlat,
                    Config("[{t: 0, yaw_rate: 0.7853981634}, {t: 2, yaw_rate: 0}]"));
  const Eigen::Vector3d p0 = Trunk(rig).translation();
  const double arm_error = RunTracking(&rig, 1.0, 4.0);
  const Pose X = Trunk(rig);
  const double yaw_deg = Yaw(X) * 180 / M_PI;
  const double drift = (X.translation() - p0).head<2>().norm();
  std::printf("[ measured ] quadruped_arm turn: yaw %.2f deg, drift %.3f m, arm error %.4f rad\n",
              yaw_deg, drift, arm_error);
  EXPECT_NEAR(yaw_deg, 90, 10);
  EXPECT_LT(drift, 0.15);
  EXPECT_LT(arm_error, 0.05);
  EXPECT_EQ(rig.probe->max_trunk_touch_n, 0.0);
}

TEST(QuadrupedArmTrot, ClimbsTheTenDegreeRamp) {
  Rig rig = MakeRig("quadruped_arm", Ground::kRamp, Config("[{t: 0, vx: 0.4}, {t: 11, vx: 0}]"));
  const double arm_error = RunTracking(&rig, 1.0, 12.0);
  WorldSnapshot snap;
  rig.sim.Snapshot(&snap);
  const double top = 2.0 * std::tan(10 * M_PI / 180);
  double min_foot_x = 1e9, min_foot_z = 1e9;
  for (const char* leg : {"FR_calf", "FL_calf", "RR_calf", "RL_calf"}) {
    const Eigen::Vector3d foot =
        snap.X_WB[rig.sim.scene().FindBody(leg)] * Eigen::Vector3d(0, 0, -0.35);
    min_foot_x = std::min(min_foot_x, foot.x());
    min_foot_z = std::min(min_foot_z, foot.z());
  }
  const Pose& X = snap.X_WB[rig.trunk];
  std::printf(
      "[ measured ] quadruped_arm ramp: trunk x = %.3f, z = %.3f; rearmost foot x = "
      "%.3f, lowest foot centre z = %.3f; arm error %.4f rad\n",
      X.translation().x(), X.translation().z(), min_foot_x, min_foot_z, arm_error);
  EXPECT_GT(min_foot_x, 3.5 + 0.05);
  EXPECT_NEAR(min_foot_z, top + 0.032, 0.01);
  EXPECT_LT(arm_error, 0.05);
  EXPECT_EQ(rig.probe->max_trunk_touch_n, 0.0);
  EXPECT_GT(rig.probe->min_up_z, 0.9);
}

TEST(QuadrupedArmTrot, SurvivesTwentyNewtonSecondLateralPush) {
  Rig rig = MakeRig("quadruped_arm", Ground::kFlat, Config("[{t: 0, vx: 0.4}]"));
  RunTracking(&rig, 0, 2.0);
  double impulse = 0, max_vy = 0;
  while (rig.sim.time() < 5.0 - 1e-9) {
    const double t = rig.sim.time();
    const bool pushing = t >= 2.0 - 1e-9 && t < 2.1 - 1e-9;
    rig.sim.ctrl()[rig.push] = pushing ? 200.0 : 0.0;
    if (pushing) impulse += 200.0 * rig.sim.timestep();
    rig.sim.Step();
    max_vy = std::max(max_vy, rig.sim.qvel()[1]);
  }
  EXPECT_NEAR(impulse, 20.0, 1e-9);
  const Pose X = Trunk(rig);
  const auto qvel = rig.sim.qvel();
  std::printf(
      "[ measured ] quadruped_arm push: peak lateral speed %.2f m/s, min up z %.3f, at "
      "5 s v = (%.2f, %.2f) m/s, yaw %.1f deg\n",
      max_vy, rig.probe->min_up_z, qvel[0], qvel[1], Yaw(X) * 180 / M_PI);
  EXPECT_GT(max_vy, 0.2);
  EXPECT_EQ(rig.probe->max_trunk_touch_n, 0.0);
  EXPECT_GT(rig.probe->min_up_z, 0.5);
  EXPECT_NEAR(qvel[0], 0.4, 0.15);
  EXPECT_LT(std::abs(qvel[1]), 0.15);
  EXPECT_LT(std::abs(Yaw(X)), 10 * M_PI / 180);
}

TEST(QuadrupedArmTrot, TwoRunsAreBitIdentical) {
  const std::string cfg = Config("[{t: 0, vx: 0.3, yaw_rate: -0.3}, {t: 1, vy: 0.2}]");
  Rig a = MakeRig("quadruped_arm", Ground::kFlat, cfg);
  Rig b = MakeRig("quadruped_arm", Ground::kFlat, cfg);
  ASSERT_TRUE(StepInLockstep(a.sim, b.sim, 1000));
  EXPECT_GT(std::abs(a.sim.qpos()[0]) + std::abs(a.sim.qpos()[1]), 0.1);
}

}  // namespace
}  // namespace penumbra
