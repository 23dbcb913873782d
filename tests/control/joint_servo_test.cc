// the joint servo's law, limits and reference profile, and joint_pd's modes, against a
// fake ControlInput (tests/control/arm_control_fake.h).

#include "penumbra/control/joint_servo.h"

#include <gtest/gtest.h>

#include <cmath>

#include "arm_control_fake.h"
#include "penumbra/control/controller_capabilities.h"
#include "penumbra/control/joint_controller.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

using namespace arm_fake;

std::unique_ptr<JointPdController> MakePd(const ModelInfo& m, const std::string& extra) {
  return Make<JointPdController>(m, "joint_pd", std::string(kServo) + extra);
}

TEST(JointServo, TorqueLawWithBiasClampAndGear) {
  const ModelInfo m = ArmModel();
  auto pd = MakePd(m, "kp: [100, 100, 100, 100, 100, 100, 10]\nkd: 5\nmax_effort: 40\n");
  ASSERT_NE(pd, nullptr);
  const JointServo& servo = pd->servo();
  FakeInput in(m);
  in.q_ = {0.1, 0.2, 0.0, -1.0, 0.0, 0.0, 0.3, 0.0};
  in.qd_ = {1.0, 0, 0, 0, 0, 0, -2.0, 0};
  in.bias_ = {3, 0, 0, 0, 0, 0, 1, 0};
  Eigen::VectorXd q_ref(7), qd_ref(7);
  q_ref << 0.3, 0.2, 1.0, -1.0, 0.0, 0.0, 0.5;
  qd_ref << 0.5, 0, 0, 0, 0, 0, 0;
  std::vector<double> ctrl(8, 7.0);
  servo.Write(in, q_ref, qd_ref, {}, ctrl);
  // tau_0 = 100 * 0.2 + 5 * (0.5 - 1) + 3 = 20.5
  EXPECT_NEAR(ctrl[0], 20.5, 1e-12);
  EXPECT_NEAR(ctrl[1], 0.0, 1e-12);
  // tau_2 = 100 * 1.0 = 100, clamped to max_effort 40
  EXPECT_NEAR(ctrl[2], 40.0, 1e-12);
  // tau_6 = 10 * 0.2 + 5 * 2 + 1 = 13 N m through gear 2: ctrl 6.5
  EXPECT_NEAR(ctrl[6], 6.5, 1e-12);
  EXPECT_NEAR(servo.last_effort()[6], 13.0, 1e-12);
  EXPECT_EQ(ctrl[7], 7.0);  // another actuator: untouched
  // without qfrc_bias from the input, gravity compensation cannot work: a clear error
  in.with_bias_ = false;
  EXPECT_THROW(servo.Write(in, q_ref, qd_ref, {}, ctrl), Error);
}

TEST(JointServo, PositionOutputWritesClampedReferences) {
  const ModelInfo m = ArmModel();
  auto pd = MakePd(m, "output: position\nlimit_margin: 0.05\n");
  FakeInput in(m);
  Eigen::VectorXd q_ref(7), qd_ref = Eigen::VectorXd::Zero(7);
  q_ref << 3.0, -0.5, 0, 0.0, 0, 0, 1.0;
  std::vector<double> ctrl(8, 0.0);
  pd->servo().Write(in, q_ref, qd_ref, {}, ctrl);
  EXPECT_NEAR(ctrl[0], 1.95, 1e-12);   // range [-2, 2] less the margin
  EXPECT_NEAR(ctrl[3], -0.15, 1e-12);  // j4's range [-3, -0.1] less the margin
  EXPECT_NEAR(ctrl[6], 2.0, 1e-12);    // gear 2: ctrl = gear * q
}

// the reference profile: straight line in joint space, within speed and acceleration,
// braking into the target without passing it
TEST(JointServo, StepTowardsIsATrapezoidWithinTheLimits) {
  const ModelInfo m = ArmModel();
  auto pd = MakePd(m, "max_velocity: 1.0\nmax_acceleration: 4.0\n");
  const JointServo& servo = pd->servo();
  Eigen::VectorXd q = Eigen::VectorXd::Zero(7), qd = Eigen::VectorXd::Zero(7);
  q[3] = -1;
  Eigen::VectorXd target = q;
  target[0] = 1.5;
  target[1] = -0.75;
  const double dt = 0.002;
  double v_max = 0, a_max = 0, t_arrive = -1;
  Eigen::VectorXd prev = qd;
  for (int k = 0; k < 2000; ++k) {
    servo.StepTowards(target, {}, dt, &q, &qd);
    v_max = std::max(v_max, qd.cwiseAbs().maxCoeff());
    a_max = std::max(a_max, ((qd - prev) / dt).cwiseAbs().maxCoeff());
    prev = qd;
    ASSERT_LE(q[0], 1.5 + 1e-12);
    // the joints move together along the line: q1 / q0 stays -1/2
    ASSERT_NEAR(q[1], -0.5 * q[0], 1e-9);
    if (t_arrive < 0 && std::abs(q[0] - 1.5) < 1e-9) t_arrive = (k + 1) * dt;
  }
  EXPECT_LE(v_max, 1.0 + 1e-9);
  EXPECT_LE(a_max, 4.0 * (1 + 1e-9));
  // trapezoid: 1.5 rad at 1 rad/s with 4 rad/s^2 ramps takes 1.5 + 1/4 = 1.75 s
  EXPECT_NEAR(t_arrive, 1.75, 0.05);
  EXPECT_NEAR(qd.norm(), 0.0, 1e-12);
  // a target moving within the limits is caught up with, then followed without lag
  Eigen::VectorXd vel = Eigen::VectorXd::Zero(7);
  vel[2] = 0.5;
  Eigen::VectorXd moving = q;
  for (int k = 0; k < 400; ++k) {
    moving[2] += 0.5 * dt;
    servo.StepTowards(moving, vel, dt, &q, &qd);
    if (k >= 300) {
      ASSERT_NEAR(q[2], moving[2], 1e-12) << k;
      ASSERT_NEAR(qd[2], 0.5, 1e-9) << k;
    }
  }
}

TEST(JointServo, BindRejectsActuatorsOfOtherJointsAndBadJoints) {
  ModelInfo m = ArmModel();
  try {
    Make<JointPdController>(m, "joint_pd", "joints: [j1, j2]\nactuators: [m1, grip]\n");
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find(
                  "world.yaml:30: robots[a].controller.actuators[1]: actuator 'a/grip' does not "
                  "drive joint 'a/j2' (it drives no joint)"),
              std::string::npos)
        << e.what();
  }
  m.joints[1].type = JointInfo::Type::kBall;
  EXPECT_THROW(Make<JointPdController>(m, "joint_pd", "joints: [j1, j2]\nactuators: [m1, m2]\n"),
               ConfigError);
}

TEST(JointPd, ModesAndCommandApi) {
  const ModelInfo m = ArmModel();
  auto pd = MakePd(m,
                   "kp: 100\nkd: 0\ngravity_compensation: false\nmax_velocity: 1\n"
                   "commands: [{t: 0.1, qd: [0.5, 0, 0, 0, 0, 0, -2]}]\n");
  FakeInput in(m);
  in.q_[3] = -1;
  std::vector<double> ctrl(8, 0.0);
  // first update: hold where the joints are
  pd->Compute(in, ctrl);
  EXPECT_NEAR(ctrl[0], 0.0, 1e-12);
  EXPECT_EQ(pd->active_command().mode, JointCommand::Mode::kPosition);
  // velocity mode from t = 0.1: the reference integrates 0.5 rad/s (and -2 clamped to -1)
  for (int k = 1; k <= 30; ++k) {
    in.t_ = 0.01 * k;
    pd->Compute(in, ctrl);
  }
  EXPECT_EQ(pd->active_command().mode, JointCommand::Mode::kVelocity);
  EXPECT_NEAR(pd->q_ref()[0], 0.5 * 0.2, 1e-9);
  EXPECT_NEAR(pd->q_ref()[6], -1.0 * 0.2, 1e-9);
  EXPECT_NEAR(ctrl[0], 100 * 0.1, 1e-9);  // kp (q_ref - q), q still 0
  // effort from another thread's point of view: SetCommand, applied at the next update
  pd->SetCommand(JointCommand::Effort({1, 2, 3, 4, 5, 6, 250}));
  in.t_ = 0.31;
  pd->Compute(in, ctrl);
  EXPECT_EQ(pd->active_command().mode, JointCommand::Mode::kEffort);
  EXPECT_NEAR(ctrl[2], 3, 1e-12);
  EXPECT_NEAR(ctrl[6], 50.0, 1e-12);  // 250 N m clamped to ctrlrange 50 x gear 2, / gear
  // back to position: the reference restarts at the measured joints
  in.q_[0] = 0.7;
  pd->PushCommand(JointCommand::Position({0.7, 0, 0, -1, 0, 0, 0}), 0.32);
  in.t_ = 0.32;
  pd->Compute(in, ctrl);
  EXPECT_NEAR(pd->q_ref()[0], 0.7, 1e-12);
  // malformed commands fail in the caller's thread
  EXPECT_THROW(pd->PushCommand(JointCommand::Position({1, 2})), Error);
  EXPECT_THROW(pd->SetCommand(JointCommand::Velocity({0, 0, 0, NAN, 0, 0, 0})), Error);
}

// what the command bus sees of a joint_pd: its JointTarget capability and nothing else
TEST(JointPd, IsAJointTargetOnly) {
  const ModelInfo m = ArmModel();
  auto pd = MakePd(m, "kp: 100\nkd: 0\n");
  ASSERT_NE(pd, nullptr);
  Controller& c = *pd;
  JointTarget* target = AsJointTarget(c);
  ASSERT_NE(target, nullptr);
  EXPECT_EQ(target->command_joints(), pd->params().servo.joints);
  EXPECT_EQ(target->command_joints().size(), 7u);
  EXPECT_EQ(AsTwistTarget(c), nullptr);
  EXPECT_EQ(AsWaypointTarget(c), nullptr);
  EXPECT_EQ(ControllerCommands(c), (std::vector<std::string>{"joint_targets"}));
  // through the interface as through the class: checked in the caller's thread, then applied
  EXPECT_THROW(target->SetCommand(JointCommand::Position({1, 2})), Error);
  target->SetCommand(JointCommand::Effort({1, 2, 3, 4, 5, 6, 7}));
  FakeInput in(m);
  std::vector<double> ctrl(8, 0.0);
  pd->Compute(in, ctrl);
  EXPECT_EQ(pd->active_command().mode, JointCommand::Mode::kEffort);
}

TEST(JointPd, ConfigErrors) {
  const ModelInfo m = ArmModel();
  auto error = [&](const std::string& extra) -> std::string {
    try {
      MakePd(m, extra);
    } catch (const ConfigError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(error("kp: [1, 2]\n")
                .find("kp: got a list of 2 items; expected a number >= 0 and <= 1e+06 or a "
                      "list of 7 such numbers (one per joint)"),
            std::string::npos);
  EXPECT_NE(error("output: effort\n").find("output: got 'effort'; expected torque or position"),
            std::string::npos);
  EXPECT_NE(error("max_velocity: 0\n").find("max_velocity: got '0'; expected a number > 0"),
            std::string::npos);
  EXPECT_NE(error("commands: [{t: 0, q: [1, 2, 3, 4, 5, 6, 7], qd: [1, 2, 3, 4, 5, 6, 7]}]\n")
                .find("commands[0]: got more than one of q / qd / tau"),
            std::string::npos);
  EXPECT_NE(error("output: position\ncommands: [{t: 0, tau: [1, 2, 3, 4, 5, 6, 7]}]\n")
                .find("commands[0].tau: effort commands need output: torque"),
            std::string::npos);
  EXPECT_NE(error("kpp: 3\n").find("unknown key(s) 'kpp'"), std::string::npos);
  EXPECT_NE(error("target: [1, 2]\n").find("target: got a list of 2 items"), std::string::npos);
  try {
    Make<JointPdController>(m, "joint_pd", "joints: [j1, j2]\nactuators: [m1]\n");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("got 1 actuators for 2 joints"), std::string::npos);
  }
  try {
    Make<JointPdController>(m, "joint_pd", "joints: [j1, j1]\nactuators: [m1, m2]\n");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("joints[1]: 'j1' is listed twice"), std::string::npos);
  }
}

}  // namespace
}  // namespace penumbra

namespace penumbra {
namespace {

using namespace arm_fake;  // NOLINT(build/namespaces)

// torque output on a position servo (a Menagerie arm's <position>) would
// write efforts as joint targets; it is refused naming the actuator and its type
TEST(JointServo, TorqueOutputRefusesServoActuators) {
  ModelInfo m = ArmModel();
  m.actuators[2].drive = ActuatorDrive::kPositionServo;
  m.actuators[2].kp = 100;
  try {
    MakePd(m, "");
    ADD_FAILURE() << "torque output accepted a position servo";
  } catch (const ConfigError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("actuators[2]: actuator '" + m.actuators[2].name +
                        "' is a position servo; expected a motor for output: torque"),
              std::string::npos)
        << what;
  }
  EXPECT_NE(MakePd(m, "output: position\n"), nullptr);
}

}  // namespace
}  // namespace penumbra
