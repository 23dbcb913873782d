// joint_pd and keyframe_playback on the bundled Panda-class arm (worlds/models/arm.xml),
// and load-time errors for configs whose names do not match the model.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "arm_test_util.h"
#include "common/temp_dir.h"
#include "penumbra/control/joint_controller.h"
#include "penumbra/control/keyframe_playback.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

using namespace arm_test;

// the arm's "reach" and "rest" keyframes (worlds/models/arm.xml)
const std::vector<double> kReach = {0, 0.3, 0, -1.9, 0, 2.2, 0.785398163};
const std::vector<double> kRest = {0, -1.3, 0, -2.9, 0, 1.65, 0.785398163};
const std::vector<double> kHome = {0, -M_PI / 4, 0, -3 * M_PI / 4, 0, M_PI / 2, M_PI / 4};

template <typename T>
T* Add(Simulation& sim, std::unique_ptr<Controller> c) {
  T* typed = dynamic_cast<T*>(c.get());
  EXPECT_NE(typed, nullptr);
  sim.AddController(std::move(c));
  return typed;
}

// steps until the controllers have run at simulated time `t` (they run at the start of a
// step, on the state at the step's start time)
void StepUntilControlAt(Simulation& sim, double t) {
  while (sim.time() < t + 0.5 * sim.timestep()) sim.Step();
}

double MaxJointError(const ArmJoints& a, std::span<const double> qpos,
                     const std::vector<double>& q) {
  double e = 0;
  for (size_t i = 0; i < q.size(); ++i) e = std::max(e, std::abs(qpos[a.qpos_adr[i]] - q[i]));
  return e;
}

TEST(ArmJointPd, PositionTargetIsReachedWithinSpeedAndJointLimits) {
  Simulation sim = Simulation::LoadFromFile(kArmXml);
  // the simulation starts in the home pose (qpos0 = the joints' ref)
  const ArmJoints a = FindArmJoints(sim.model_info());
  EXPECT_LT(MaxJointError(a, sim.qpos(), kHome), 1e-8);  // 9-digit refs in the MJCF
  // joint 4 is sent past its upper bound (-0.0698 rad): the target is clamped inside it
  auto* pd = Add<JointPdController>(
      sim,
      MakeController(Block("joint_pd", ServoBlock() + "commands:\n"
                                                      "  - {t: 0.2, q: [0.5, 0.3, -0.4, 0.3, 0.6, "
                                                      "2.2, 0.0]}\n"),
                     "", "arm.yaml"));
  const double vmax[7] = {2.175, 2.175, 2.175, 2.175, 2.61, 2.61, 2.61};
  double worst_violation = 0, worst_speed_ratio = 0;
  std::vector<double> prev(sim.qpos().begin(), sim.qpos().end());
  while (sim.time() < 3.0) {
    sim.Step();
    worst_violation = std::max(worst_violation, LimitViolation(a, sim.qpos()));
    for (int i = 0; i < 7; ++i)
      worst_speed_ratio =
          std::max(worst_speed_ratio, std::abs(sim.qvel()[a.qpos_adr[i]]) / vmax[i]);
  }
  const std::vector<double> expected = {0.5, 0.3, -0.4, a.hi[3] - 0.01, 0.6, 2.2, 0.0};
  std::printf("final error %.2e rad, worst speed %.0f %% of the limit\n",
              MaxJointError(a, sim.qpos(), expected), worst_speed_ratio * 100);
  EXPECT_LT(MaxJointError(a, sim.qpos(), expected), 1e-3);
  EXPECT_LE(worst_violation, 0.0);
  EXPECT_LT(worst_speed_ratio, 1.1);  // the reference moves at the limit; the joints follow
  EXPECT_EQ(pd->active_command().mode, JointCommand::Mode::kPosition);
}

TEST(ArmJointPd, VelocityAndEffortModes) {
  Simulation sim = Simulation::LoadFromFile(kArmXml);
  const ArmJoints a = FindArmJoints(sim.model_info());
  auto* pd = Add<JointPdController>(
      sim, MakeController(
               Block("joint_pd", ServoBlock() + "commands:\n"
                                                "  - {t: 0.5, qd: [0.4, 0, 0, 0, 0, 0, -0.3]}\n"
                                                "  - {t: 1.5, qd: [0, 0, 0, 0, 0, 0, 0]}\n"
                                                "  - {t: 2.5, tau: [0, 0, 0, 0, 0, 0, 0]}\n"),
               "", "arm.yaml"));
  while (sim.time() < 2.5 - 1e-9) sim.Step();
  // 1 s at 0.4 rad/s and -0.3 rad/s from home, then holding
  std::vector<double> moved = kHome;
  moved[0] += 0.4;
  moved[6] -= 0.3;
  EXPECT_LT(MaxJointError(a, sim.qpos(), moved), 2e-3);
  EXPECT_EQ(pd->active_command().mode, JointCommand::Mode::kVelocity);
  // zero effort plus gravity/Coriolis compensation (qfrc_bias): the arm floats in place,
  // slowed by joint damping
  const std::vector<double> before(sim.qpos().begin(), sim.qpos().begin() + 7);
  while (sim.time() < 3.5) sim.Step();
  EXPECT_EQ(pd->active_command().mode, JointCommand::Mode::kEffort);
  EXPECT_LT(MaxJointError(a, sim.qpos(), before), 5e-3);
  // the same without compensation: the arm falls
  Simulation limp = Simulation::LoadFromFile(kArmXml);
  Add<JointPdController>(
      limp,
      MakeController(
          Block("joint_pd", ServoBlock(false) + "commands: [{t: 0, tau: [0, 0, 0, 0, 0, 0, 0]}]\n"),
          "", "arm.yaml"));
  while (limp.time() < 0.5) limp.Step();
  EXPECT_GT(MaxJointError(a, limp.qpos(), kHome), 0.1);
}

// MJCF keys and explicit frames, interpolated; the gripper follows the keys' finger values
TEST(ArmKeyframePlayback, PlaysMjcfKeysWithLinearInterpolation) {
  Simulation sim = Simulation::LoadFromFile(kArmXml);
  const ArmJoints a = FindArmJoints(sim.model_info());
  auto* kp = Add<KeyframePlayback>(
      sim, MakeController(Block("keyframe_playback", ServoBlock() + "gripper_actuator: gripper\n"
                                                                    "gripper_joint: finger_joint1\n"
                                                                    "frames:\n"
                                                                    "  - {t: 0.5, key: home}\n"
                                                                    "  - {t: 2.5, key: reach}\n"
                                                                    "  - {t: 3.0, key: reach}\n"
                                                                    "  - {t: 5.0, key: rest}\n"),
                          "", "arm.yaml"));
  const int finger = sim.model_info().Find(ModelObject::kJoint, "finger_joint1");
  const int fa = sim.model_info().joints[finger].qpos_adr;
  double worst_violation = 0, worst_lag = 0;
  while (sim.time() < 6.0) {
    sim.Step();
    worst_violation = std::max(worst_violation, LimitViolation(a, sim.qpos()));
    const double t_ctrl = sim.time() - sim.timestep();  // time of the last control update
    // halfway between home and reach at t = 1.5
    if (std::abs(t_ctrl - 1.5) < 1e-6) {
      std::vector<double> mid(7);
      for (int i = 0; i < 7; ++i) mid[i] = 0.5 * (kHome[i] + kReach[i]);
      for (int i = 0; i < 7; ++i) EXPECT_NEAR(kp->target()[i], mid[i], 1e-6);
      worst_lag = std::max(worst_lag, MaxJointError(a, sim.qpos(), mid));
    }
    if (std::abs(t_ctrl - 3.0) < 1e-6) {
      EXPECT_LT(MaxJointError(a, sim.qpos(), kReach), 5e-3);
      EXPECT_NEAR(sim.qpos()[fa], 0.04, 1e-3);  // "reach" has the gripper open
    }
  }
  std::printf("tracking lag at t = 1.5 s: %.4f rad\n", worst_lag);
  EXPECT_LT(worst_lag, 0.02);
  EXPECT_TRUE(kp->finished());
  EXPECT_LT(MaxJointError(a, sim.qpos(), kRest), 1e-3);
  EXPECT_NEAR(sim.qpos()[fa], 0.0, 1e-3);  // "rest" has it closed
  EXPECT_LE(worst_violation, 0.0);
}

TEST(ArmKeyframePlayback, PlaysACsvRelativeToTheWorldFile) {
  const std::filesystem::path dir = std::filesystem::path(penumbra::testing::ProcessTempDir());
  std::filesystem::create_directories(dir / "motions");
  {
    std::ofstream csv(dir / "motions" / "wave.csv");
    csv << "# a wave of joint 1 and joint 7, columns in a different order than the joints\n"
           "time_sec,joint7,joint1,joint2,joint3,joint4,joint5,joint6\n"
           "0.0, 0.785398163, 0.0, -0.785398163, 0, -2.35619449, 0, 1.57079633\n"
           "1.0, 1.285398163, 0.6, -0.785398163, 0, -2.35619449, 0, 1.57079633\n"
           "\n"
           "2.0, 0.285398163, -0.6, -0.785398163, 0, -2.35619449, 0, 1.57079633\n";
  }
  Simulation sim = Simulation::LoadFromFile(kArmXml);
  const ArmJoints a = FindArmJoints(sim.model_info());
  auto* kp = Add<KeyframePlayback>(
      sim, MakeController(
               Block("keyframe_playback", ServoBlock() + "csv: motions/wave.csv\nloop: true\n"), "",
               (dir / "world.yaml").string()));
  EXPECT_EQ(kp->params().frames.size(), 3u);
  StepUntilControlAt(sim, 1.5);
  // halfway from (0.6, 1.285) to (-0.6, 0.285)
  EXPECT_NEAR(kp->target()[0], 0.0, 1e-6);
  EXPECT_NEAR(kp->target()[6], 0.785398163, 1e-6);
  // looping with a period of 2 s (the last frame's time): t = 2.5 s is 0.5 s into the
  // second lap, halfway from frame 0 to frame 1
  StepUntilControlAt(sim, 2.5);
  EXPECT_NEAR(kp->target()[0], 0.3, 1e-6);
  EXPECT_FALSE(kp->finished());
  while (sim.time() < 3.0 - 1e-9) sim.Step();
  EXPECT_LT(std::abs(sim.qpos()[a.qpos_adr[0]] - 0.6), 0.02);
  std::filesystem::remove_all(dir);
}

// a config whose names are not in the model fails when the controller is added (at load),
// with one message listing every missing name, its kind and its config key
TEST(ArmControllers, WrongNamesFailAtLoadListingEveryMissingName) {
  Simulation sim = Simulation::LoadFromFile(kSceneXml);
  const std::string servo =
      "joints: [joint1, joint2, joint_3, joint4, joint5, joint6, wrist]\n"
      "actuators: [actuator1, actuator2, actuator3, actuator4, actuator5, actuator6, motor7]\n";
  try {
    sim.AddController(MakeController(
        Block("diff_ik", servo + "site: tcp\nbase_body: link0\ngripper_actuator: hand\n", 21), "",
        "worlds/arm.yaml"));
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    const std::string msg = e.what();
    std::printf("%s\n", msg.c_str());
    EXPECT_EQ(e.file(), "worlds/arm.yaml");
    EXPECT_EQ(e.line(), 21);
    EXPECT_NE(msg.find("5 names not found"), std::string::npos);
    EXPECT_NE(msg.find("joints[2]: joint 'joint_3'"), std::string::npos);
    EXPECT_NE(msg.find("joints[6]: joint 'wrist'"), std::string::npos);
    EXPECT_NE(msg.find("actuators[6]: actuator 'motor7'"), std::string::npos);
    EXPECT_NE(msg.find("site: site 'tcp'"), std::string::npos);
    EXPECT_NE(msg.find("gripper_actuator: actuator 'hand'"), std::string::npos);
    EXPECT_NE(msg.find("'joint1'"), std::string::npos);  // hint: names that do exist
  }
  // the same for joint_pd and for keyframe names of keyframe_playback
  EXPECT_THROW(sim.AddController(MakeController(Block("joint_pd", servo), "", "w.yaml")),
               ConfigError);
  try {
    sim.AddController(
        MakeController(Block("keyframe_playback",
                             ServoBlock() + "frames: [{t: 1, key: home}, {t: 2, key: wave}]\n"),
                       "", "w.yaml"));
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("frames[1].key: keyframe 'wave'"), std::string::npos)
        << e.what();
  }
  // names prefixed for a robot the model does not have: every name is listed
  try {
    sim.AddController(MakeController(Block("joint_pd", ServoBlock()), "panda", "w.yaml"));
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("14 names not found"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("joint 'panda/joint1'"), std::string::npos);
  }
  // an actuator that exists but drives another joint
  try {
    sim.AddController(MakeController(
        Block("joint_pd", "joints: [joint1, joint2]\nactuators: [actuator2, actuator1]\n"), "",
        "w.yaml"));
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("actuators[0]"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("does not drive joint 'joint1'"), std::string::npos);
  }
  EXPECT_EQ(sim.num_controllers(), 0);
}

}  // namespace
}  // namespace penumbra
