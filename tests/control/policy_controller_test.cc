// the policy controller end to end on a hand-made quadruped: YAML block -> observation ->
// ONNX network (fixtures made by tests/control/fixtures/make_policy_fixtures.py) -> actuator
// ctrl, the refusals at load, the presets and the velocity-command interface.

#include "penumbra/control/policy_controller.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>

#include "common/temp_dir.h"
#include "control/policy_fake.h"
#include "penumbra/config/yaml_document.h"
#include "penumbra/control/policy_preset.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

using policy_fake::MakePolicy;
using policy_fake::QuadInput;
using policy_fake::QuadModel;

// the 12 joints in an order unlike the model's (j11 .. j0)
const char* kReversedJoints =
    "base_body: trunk\n"
    "joints: [j11, j10, j9, j8, j7, j6, j5, j4, j3, j2, j1, j0]\n";

std::string PolicyErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

PolicyController* AsPolicy(const std::unique_ptr<Controller>& c) {
  return dynamic_cast<PolicyController*>(c.get());
}

TEST(PolicyControllerTest, IdentityGraphDrivesJointTargetsThroughPd) {
  // gemm_15x12: action_j = observation[3 + j]; observations [velocity_command, joint_pos]:
  // the action is the policy joint's offset from its default, so with scale 0.5 the target
  // is q_default + 0.5 (q - q_default) and the motors get tau = kp (target - q) - kd qdot
  const ModelInfo m = QuadModel();
  auto c = MakePolicy(std::string(kReversedJoints) +
                      "model: gemm_15x12.onnx\n"
                      "default_joint_pos: {'j1[01]': 0.4, 'j[0-9]+': -0.2}\n"
                      "decimation: 2\n"
                      "observations: [{term: velocity_command}, {term: joint_pos}]\n"
                      "action: {type: joint_position, scale: 0.5, kp: 20, kd: 0.5}\n");
  PolicyController* p = AsPolicy(c);
  ASSERT_NE(p, nullptr);
  c->Initialize(m);
  EXPECT_EQ(p->observation().size(), 15);
  EXPECT_EQ(p->decimation(), 2);
  QuadInput in(m);
  for (int i = 0; i < 12; ++i) {
    in.q_[7 + i] = 0.05 * i - 0.1;
    in.qd_[6 + i] = 0.1 * (i % 3) - 0.1;
  }
  std::vector<double> ctrl(m.nu, 0.0);
  c->Compute(in, ctrl);
  for (int i = 0; i < 12; ++i) {
    const double d = (i == 10 || i == 11) ? 0.4 : -0.2;  // first matching pattern wins
    const double q = in.q_[7 + i], qd = in.qd_[6 + i];
    const double target = d + 0.5 * (q - d);
    const double gear = i == 5 ? 2.0 : 1.0;
    const double expected = (20 * (target - q) - 0.5 * qd) / gear;
    EXPECT_NEAR(ctrl[i], expected, 1e-5) << "model joint j" << i;
    // the policy-order views: policy joint 11 - i is model joint i
    EXPECT_NEAR(p->targets()[11 - i], target, 1e-6);
    EXPECT_NEAR(p->default_positions()[11 - i], d, 0);
  }
  // next step (no policy update at decimation 2): the PD law runs on the new state with the
  // held targets
  const Eigen::VectorXd held = p->targets();
  in.q_[7] += 0.01;
  c->Compute(in, ctrl);
  EXPECT_NEAR(ctrl[0], 20 * (held[11] - in.q_[7]) - 0.5 * in.qd_[6], 1e-5);
  EXPECT_EQ(p->targets(), held);
  // the third step is a policy update: the target follows the new q
  c->Compute(in, ctrl);
  EXPECT_NEAR(p->targets()[11], -0.2 + 0.5 * (in.q_[7] + 0.2), 1e-6);
}

TEST(PolicyControllerTest, PositionServosGetTheTargetAsCtrl) {
  const ModelInfo m = QuadModel(/*position_servos=*/true);
  auto c = MakePolicy(std::string(kReversedJoints) +
                      "model: gemm_15x12.onnx\n"
                      "default_joint_pos: [0.1, 0.1, 0.1, 0.1, 0.1, 0.1, 0.1, 0.1, 0.1, 0.1, "
                      "0.1, 0.1]\n"
                      "observations: [{term: velocity_command}, {term: joint_pos}]\n"
                      "action: {scale: 2, clip: 0.3}\n");
  c->Initialize(m);
  QuadInput in(m);
  for (int i = 0; i < 12; ++i) in.q_[7 + i] = 0.1 + 0.02 * i;
  std::vector<double> ctrl(m.nu, 0.0);
  c->Compute(in, ctrl);
  for (int i = 0; i < 12; ++i) {
    // raw action = q - 0.1 = 0.02 i, clipped to 0.3; target = 0.1 + 2 a; ctrl = gear target
    const double a = std::min(0.02 * i, 0.3);
    const double gear = i == 5 ? 2.0 : 1.0;
    EXPECT_NEAR(ctrl[i], gear * (0.1 + 2 * a), 1e-5) << i;
  }
  EXPECT_NEAR(AsPolicy(c)->last_action()[0], 0.22, 1e-6);  // policy joint 0 = j11, 0.22 < 0.3
}

TEST(PolicyControllerTest, MotorsWithoutGainsAreRefusedForPositionTargets) {
  const ModelInfo m = QuadModel();
  auto c = MakePolicy(std::string(kReversedJoints) +
                      "model: gemm_15x12.onnx\n"
                      "observations: [{term: velocity_command}, {term: joint_pos}]\n");
  const std::string e = PolicyErrorOf([&] { c->Initialize(m); });
  EXPECT_NE(e.find("robots[q].controller.joints[0]"), std::string::npos) << e;
  EXPECT_NE(e.find("actuator 'q/j11' is a motor"), std::string::npos) << e;
  EXPECT_NE(e.find("action.kp and action.kd"), std::string::npos) << e;
}

TEST(PolicyControllerTest, RefusesAMissingModelFile) {
  const std::string e = PolicyErrorOf([] {
    MakePolicy(std::string(kReversedJoints) +
               "model: no_such_policy.onnx\n"
               "observations: [{term: joint_pos}]\n");
  });
  EXPECT_NE(e.find("robots[q].controller.model"), std::string::npos) << e;
  EXPECT_NE(e.find("tests/control/fixtures/no_such_policy.onnx"), std::string::npos) << e;
  EXPECT_NE(e.find("expected an ONNX policy"), std::string::npos) << e;
}

TEST(PolicyControllerTest, RefusesAGarbageFileNamingIt) {
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / "policy_garbage";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "garbage.onnx").string();
  {
    std::ofstream f(path, std::ios::binary);
    f << "this is not a protobuf \x01\x02\x03\xff\xfe";
  }
  ControllerConfig cfg;
  cfg.type = "policy";
  cfg.params = ParseYaml("type: policy\n" + std::string(kReversedJoints) + "model: " + path +
                         "\nobservations: [{term: velocity_command}, {term: joint_pos}]\n"
                         "action: {kp: 20, kd: 0.5}\n");
  auto c = MakeController(cfg, "q", "/elsewhere/world.yaml");
  const ModelInfo m = QuadModel();
  const std::string e = PolicyErrorOf([&] { c->Initialize(m); });
  EXPECT_EQ(e.rfind(path, 0), 0u) << e;  // the message starts with the file
  EXPECT_NE(e.find("not a valid ONNX (protobuf) file"), std::string::npos) << e;
}

TEST(PolicyControllerTest, RefusesAGraphOfTheWrongInputSize) {
  // 14 observations (joint_pos + phase would be 14, here velocity_command dropped: 12 + 2)
  const ModelInfo m = QuadModel();
  auto c = MakePolicy(std::string(kReversedJoints) +
                      "model: gemm_15x12.onnx\n"
                      "observations: [{term: joint_pos}, {term: phase, period_sec: 1}]\n"
                      "action: {kp: 20, kd: 0.5}\n");
  const std::string e = PolicyErrorOf([&] { c->Initialize(m); });
  EXPECT_NE(e.find("gemm_15x12.onnx"), std::string::npos) << e;
  EXPECT_NE(e.find("graph input 'obs' has shape [1, 15]"), std::string::npos) << e;
  EXPECT_NE(e.find("expected [1, 14] (the configured observation size)"), std::string::npos) << e;
}

TEST(PolicyControllerTest, RefusesAGraphOfTheWrongOutputSize) {
  // 11 joints: 3 + 11 + 1 contact = 15 observations fit, but the graph returns 12 actions
  const ModelInfo m = QuadModel();
  auto c = MakePolicy(
      "base_body: trunk\n"
      "joints: [j0, j1, j2, j3, j4, j5, j6, j7, j8, j9, j10]\n"
      "model: gemm_15x12.onnx\n"
      "observations: [{term: velocity_command}, {term: joint_pos}, "
      "{term: contact, sensors: [touch0]}]\n"
      "action: {kp: 20, kd: 0.5}\n");
  const std::string e = PolicyErrorOf([&] { c->Initialize(m); });
  EXPECT_NE(e.find("gemm_15x12.onnx"), std::string::npos) << e;
  EXPECT_NE(e.find("graph output 'actions' declares shape [1, 12]"), std::string::npos) << e;
  EXPECT_NE(e.find("expected 11 values (one per policy joint)"), std::string::npos) << e;
}

TEST(PolicyControllerTest, RefusesAnOperatorOpenCvCannotServe) {
  const ModelInfo m = QuadModel();
  auto c = MakePolicy(std::string(kReversedJoints) +
                      "model: unsupported_op.onnx\n"
                      "observations: [{term: joint_pos}]\n"
                      "action: {kp: 20, kd: 0.5}\n");
  const std::string e = PolicyErrorOf([&] { c->Initialize(m); });
  EXPECT_NE(e.find("unsupported_op.onnx"), std::string::npos) << e;
  EXPECT_NE(e.find("Loop"), std::string::npos) << e;
}

TEST(PolicyControllerTest, RefusesAnActionScaleOutOfBoundsWithItsLine) {
  const std::string e = PolicyErrorOf([] {
    MakePolicy(std::string(kReversedJoints) +
               "model: gemm_15x12.onnx\n"
               "observations: [{term: velocity_command}, {term: joint_pos}]\n"
               "action: {scale: 1e308, kp: 20, kd: 0.5}\n");
  });
  EXPECT_NE(e.find("world.yaml:"), std::string::npos) << e;
  EXPECT_NE(e.find("action.scale"), std::string::npos) << e;
  EXPECT_NE(e.find("|scale| <= 1e4"), std::string::npos) << e;
  const std::string clip = PolicyErrorOf([] {
    MakePolicy(std::string(kReversedJoints) +
               "model: gemm_15x12.onnx\n"
               "observations: [{term: velocity_command}, {term: joint_pos}]\n"
               "action: {clip: 1e300, kp: 20, kd: 0.5}\n");
  });
  EXPECT_NE(clip.find("action.clip"), std::string::npos) << clip;
  EXPECT_NE(clip.find("expected a number in (0, 1e6]"), std::string::npos) << clip;
  // the observation terms' scale, clip and noise likewise
  const std::string obs = PolicyErrorOf([] {
    MakePolicy(std::string(kReversedJoints) +
               "model: gemm_15x12.onnx\n"
               "observations: [{term: velocity_command}, {term: joint_pos, scale: 1e308}]\n"
               "action: {kp: 20, kd: 0.5}\n");
  });
  EXPECT_NE(obs.find("world.yaml:"), std::string::npos) << obs;
  EXPECT_NE(obs.find("observations[1].scale"), std::string::npos) << obs;
  EXPECT_NE(obs.find("|scale| <= 1e4"), std::string::npos) << obs;
  const std::string noise = PolicyErrorOf([] {
    MakePolicy(std::string(kReversedJoints) +
               "model: gemm_15x12.onnx\n"
               "observations: [{term: velocity_command}, {term: joint_pos, noise: 1e300}]\n"
               "action: {kp: 20, kd: 0.5}\n");
  });
  EXPECT_NE(noise.find("observations[1].noise"), std::string::npos) << noise;
}

TEST(PolicyControllerTest, APolicyFileThatIsNotARegularFileIsRefusedAsSuch) {
  // a FIFO was reported as "no such file"; it must not block either
  testing::TempDir dir;
  const std::string fifo = (dir.path() / "policy.onnx").string();
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  const std::string e = PolicyErrorOf([&] {
    MakePolicy(std::string(kReversedJoints) + "model: " + fifo +
               "\nobservations: [{term: joint_pos}]\n");
  });
  EXPECT_NE(e.find("robots[q].controller.model"), std::string::npos) << e;
  EXPECT_NE(e.find("is not a regular file; expected an ONNX policy file"), std::string::npos) << e;
}

TEST(PolicyControllerTest, ANonFiniteObservationStopsTheRunNamingStepAndTerm) {
  // a joint position of 1e36 rad scaled by 1e4 overflows float32: the run stops before the
  // network runs
  const ModelInfo m = QuadModel();
  auto c = MakePolicy(std::string(kReversedJoints) +
                      "model: gemm_15x12.onnx\n"
                      "decimation: 2\n"
                      "observations: [{term: velocity_command}, {term: joint_pos, scale: 1e4}]\n"
                      "action: {kp: 20, kd: 0.5}\n");
  c->Initialize(m);
  QuadInput in(m);
  std::vector<double> ctrl(m.nu, 0.0);
  c->Compute(in, ctrl);  // q = default: joint_pos 0
  c->Compute(in, ctrl);
  in.q_[7 + 11] = 1e36;  // model joint j11 = policy joint 0
  const std::string e = PolicyErrorOf([&] { c->Compute(in, ctrl); });
  EXPECT_NE(e.find("policy step 2"), std::string::npos) << e;
  EXPECT_NE(e.find("observation 3, observations[1] (joint_pos) element 0, history frame 0 of 1"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("expected a finite value"), std::string::npos) << e;
}

TEST(PolicyControllerTest, RefusesBadBlocksByKey) {
  EXPECT_NE(PolicyErrorOf([] {
              MakePolicy(std::string(kReversedJoints) +
                         "model: gemm_15x12.onnx\nobservations: [{term: joint_speed}]\n");
            }).find("observations[0].term: unknown term 'joint_speed'"),
            std::string::npos);
  EXPECT_NE(PolicyErrorOf([] {
              MakePolicy(std::string(kReversedJoints) + "model: gemm_15x12.onnx\npreset: rsl\n");
            }).find("preset: unknown preset 'rsl'; expected one of: legged_gym"),
            std::string::npos);
  EXPECT_NE(PolicyErrorOf([] {
              MakePolicy(std::string(kReversedJoints) +
                         "model: gemm_15x12.onnx\nobservations: [{term: joint_pos}]\n"
                         "rate_hz: 50\ndecimation: 4\n");
            }).find("decimation: given together with rate_hz"),
            std::string::npos);
  EXPECT_NE(PolicyErrorOf([] {
              MakePolicy(std::string(kReversedJoints) +
                         "model: gemm_15x12.onnx\nobservations: [{term: joint_pos}]\n"
                         "action: {type: joint_torque, kp: 3}\n");
            }).find("action.kp: not used by joint_torque"),
            std::string::npos);
  EXPECT_NE(PolicyErrorOf([] {
              MakePolicy(std::string(kReversedJoints) +
                         "model: gemm_15x12.onnx\nobservations: [{term: joint_pos, history: 0}]\n");
            }).find("observations[0].history"),
            std::string::npos);
  // a rate that is not a whole number of 5 ms steps
  const ModelInfo m = QuadModel();
  auto c = MakePolicy(std::string(kReversedJoints) +
                      "model: gemm_15x12.onnx\nrate_hz: 30\n"
                      "observations: [{term: velocity_command}, {term: joint_pos}]\n"
                      "action: {kp: 20, kd: 0.5}\n");
  EXPECT_NE(PolicyErrorOf([&] { c->Initialize(m); }).find("not a whole number of physics steps"),
            std::string::npos);
}

TEST(PolicyControllerTest, PresetsGiveTheirConventionsTermOrderAndScales) {
  // 48 observations for 12 joints in each convention; the fixture MLP takes 48
  const ModelInfo m = QuadModel();
  QuadInput in(m);
  in.V_WB_ << 0.4, 0.0, 0.8, 1.0, 0.0, 0.0;  // identity pose: body frame = world frame
  for (int i = 0; i < 12; ++i) in.qd_[6 + i] = 2.0;
  for (const char* preset : {"legged_gym", "isaac_lab", "mjlab"}) {
    auto c = MakePolicy(std::string(kReversedJoints) + "model: mlp_48x12.onnx\npreset: " + preset +
                        "\naction: {scale: 0.25, kp: 20, kd: 0.5}\n" +
                        "commands: [{t: 0, vx: 0.5, vy: 0.25, yaw_rate: 1.0}]\n");
    c->Initialize(m);
    PolicyController* p = AsPolicy(c);
    ASSERT_EQ(p->observation().size(), 48) << preset;
    EXPECT_EQ(p->decimation(), 4) << preset;  // 50 Hz on 5 ms steps
    std::vector<double> ctrl(m.nu, 0.0);
    c->Compute(in, ctrl);
    const std::vector<float>& o = p->last_observation();
    const std::string name = preset;
    if (name == "legged_gym") {
      // lin_vel x2 | ang_vel x0.25 | gravity | command x(2, 2, 0.25) | q | qdot x0.05 | a
      EXPECT_FLOAT_EQ(o[0], 2.0f);
      EXPECT_FLOAT_EQ(o[3], 0.1f);
      EXPECT_FLOAT_EQ(o[5], 0.2f);
      EXPECT_FLOAT_EQ(o[8], -1.0f);
      EXPECT_FLOAT_EQ(o[9], 1.0f);
      EXPECT_FLOAT_EQ(o[10], 0.5f);
      EXPECT_FLOAT_EQ(o[11], 0.25f);
      EXPECT_FLOAT_EQ(o[24], 0.1f);
    } else if (name == "isaac_lab") {
      // lin_vel | ang_vel | gravity | command | q | qdot | a, unscaled
      EXPECT_FLOAT_EQ(o[0], 1.0f);
      EXPECT_FLOAT_EQ(o[3], 0.4f);
      EXPECT_FLOAT_EQ(o[9], 0.5f);
      EXPECT_FLOAT_EQ(o[11], 1.0f);
      EXPECT_FLOAT_EQ(o[24], 2.0f);
    } else {
      // lin_vel | ang_vel | gravity | q | qdot | a | command
      EXPECT_FLOAT_EQ(o[0], 1.0f);
      EXPECT_FLOAT_EQ(o[8], -1.0f);
      EXPECT_FLOAT_EQ(o[21], 2.0f);
      EXPECT_FLOAT_EQ(o[45], 0.5f);
      EXPECT_FLOAT_EQ(o[47], 1.0f);
    }
    // last_action is 0 at the first update, then the previous output
    EXPECT_FLOAT_EQ(o[name == "mjlab" ? 33 : 36], 0.0f);
    const double first = p->last_action()[0];
    for (int k = 0; k < 4; ++k) c->Compute(in, ctrl);
    const std::vector<float>& o2 = p->last_observation();
    EXPECT_FLOAT_EQ(o2[name == "mjlab" ? 33 : 36], static_cast<float>(first)) << preset;
  }
}

TEST(PolicyControllerTest, RoughPresetsAddTheirHeightScan) {
  PolicyPreset lg = MakePolicyPreset(PolicyConvention::kLeggedGymRough);
  PolicyPreset il = MakePolicyPreset(PolicyConvention::kIsaacLabRough);
  ASSERT_EQ(lg.observations.back().kind, ObservationTermKind::kHeightScan);
  ASSERT_EQ(il.observations.back().kind, ObservationTermKind::kHeightScan);
  // 17 x 11 = 187 points (legged_gym's measured_points_x / _y; Isaac Lab's 1.6 x 1.0 at 0.1)
  EXPECT_EQ(lg.observations.back().grid.nx() * lg.observations.back().grid.ny(), 187);
  EXPECT_EQ(il.observations.back().grid.nx() * il.observations.back().grid.ny(), 187);
  EXPECT_FALSE(lg.observations.back().grid.x_fastest);
  EXPECT_TRUE(il.observations.back().grid.x_fastest);
}

TEST(PolicyControllerTest, TakesVelocityCommandsLikeTrotGait) {
  const ModelInfo m = QuadModel();
  auto c = MakePolicy(std::string(kReversedJoints) +
                      "model: gemm_15x12.onnx\n"
                      "observations: [{term: velocity_command}, {term: joint_pos}]\n"
                      "action: {kp: 20, kd: 0.5}\n"
                      "commands: [{t: 0, vx: 0.3}, {t: 1, yaw_rate: 0.5}]\n");
  c->Initialize(m);
  TwistTarget* twist = AsTwistTarget(*c);
  ASSERT_NE(twist, nullptr);
  EXPECT_TRUE(twist->lateral());
  EXPECT_EQ(ControllerCommands(*c), (std::vector<std::string>{"twist", "waypoints"}));
  PolicyController* p = AsPolicy(c);
  QuadInput in(m);
  std::vector<double> ctrl(m.nu, 0.0);
  c->Compute(in, ctrl);
  EXPECT_FLOAT_EQ(p->last_observation()[0], 0.3f);  // scripted
  twist->SetTwist(TrotCommand{-0.2, 0.1, 0.4});
  for (int k = 0; k < 10; ++k) c->Compute(in, ctrl);  // decimation 4 at 50 Hz / 5 ms
  EXPECT_FLOAT_EQ(p->last_observation()[0], -0.2f);
  EXPECT_FLOAT_EQ(p->last_observation()[1], 0.1f);
  EXPECT_FLOAT_EQ(p->last_observation()[2], 0.4f);
  twist->ClearTwist();
  in.t_ = 1.5;
  for (int k = 0; k < 4; ++k) c->Compute(in, ctrl);
  EXPECT_FLOAT_EQ(p->last_observation()[0], 0.0f);
  EXPECT_FLOAT_EQ(p->last_observation()[2], 0.5f);
  // a route: pure pursuit towards a point straight ahead gives vx > 0, no yaw
  AsWaypointTarget(*c)->SetWaypoints({Eigen::Vector2d(3, 0)}, false);
  for (int k = 0; k < 4; ++k) c->Compute(in, ctrl);
  EXPECT_GT(p->last_observation()[0], 0.0f);
  EXPECT_NEAR(p->last_observation()[2], 0.0f, 1e-6);
  // the tracking error reports command minus the measured (zero) base velocity
  std::vector<double> err;
  c->AppendTrackingError(&err);
  ASSERT_EQ(err.size(), 3u);
  EXPECT_NEAR(err[0], p->command().vx, 1e-12);
}

}  // namespace
}  // namespace penumbra
