// the policy controller on the bundled quadruped in MuJoCo: the zero ("stand") policy of
// worlds/policies holds the default pose through PD on the torque motors, and a policy run is
// bit-identical between two simulations, with seeded observation noise.

#include <gtest/gtest.h>

#include "penumbra/config/yaml_document.h"
#include "penumbra/control/policy_controller.h"
#include "physics/quadruped_test_util.h"

namespace penumbra {
namespace {

using quadruped_test::Ground;
using quadruped_test::kModelsDir;
using quadruped_test::SceneXml;

// a policy block for the bundled quadruped (unprefixed names), joints in Isaac Lab's order
// (all hips, then thighs, then calves), unlike the model's leg-by-leg order
std::string PolicyYaml(const std::string& model, const std::string& extra) {
  return "type: policy\n"
         "model: " +
         model +
         "\n"
         "preset: isaac_lab\n"
         "base_body: trunk\n"
         "joints: [FL_hip, FR_hip, RL_hip, RR_hip, FL_thigh, FR_thigh, RL_thigh, RR_thigh,\n"
         "         FL_calf, FR_calf, RL_calf, RR_calf]\n"
         "default_joint_pos: {'.*_hip': 0.0, '.*_thigh': 0.9, '.*_calf': -1.8}\n"
         "action: {scale: 0.25, kp: 80, kd: 2.0}\n" +
         extra;
}

Simulation PolicySim(const std::string& model, const std::string& extra,
                     PolicyController** policy) {
  Simulation sim =
      Simulation::LoadFromString(SceneXml("quadruped", Ground::kFlat), std::nullopt, kModelsDir);
  ControllerConfig cfg;
  cfg.type = "policy";
  cfg.line = 1;
  cfg.params = ParseYaml(PolicyYaml(model, extra));
  std::unique_ptr<Controller> c =
      MakeController(cfg, "", PENUMBRA_SOURCE_DIR "/worlds/policy_test.yaml");
  *policy = dynamic_cast<PolicyController*>(c.get());
  sim.AddController(std::move(c));
  return sim;
}

TEST(QuadrupedPolicyTest, StandPolicyHoldsTheDefaultPose) {
  PolicyController* policy = nullptr;
  Simulation sim = PolicySim("policies/stand_48x12.onnx", "", &policy);
  ASSERT_NE(policy, nullptr);
  EXPECT_EQ(policy->observation().size(), 48);
  const int trunk = sim.scene().FindBody("trunk");
  while (sim.time() < 2.0 - 1e-9) sim.Step();
  WorldSnapshot snap;
  sim.Snapshot(&snap);
  const Pose X = snap.X_WB[trunk];
  // standing: trunk origin 0.285 m over the floor at the model's qpos0 (the same pose)
  EXPECT_GT(X.translation().z(), 0.22);
  EXPECT_LT(X.translation().z(), 0.32);
  EXPECT_GT(X.linear()(2, 2), 0.99);  // upright within 8 deg
  // the action was 0, so the targets are the default pose, and the joints hold it within the
  // PD's steady-state error (gravity torque / kp: the rear calves carry about 7 N m, 0.09 rad
  // at kp 80)
  const ModelInfo& mi = sim.model_info();
  for (size_t j = 0; j < policy->params().joints.size(); ++j) {
    const std::string& name = policy->params().joints[j];
    const double q = sim.qpos()[mi.joints[mi.Find(ModelObject::kJoint, name)].qpos_adr];
    EXPECT_NEAR(policy->targets()[j], policy->default_positions()[j], 1e-12) << name;
    EXPECT_NEAR(q, policy->default_positions()[j], 0.15) << name;
  }
}

TEST(QuadrupedPolicyTest, PolicyRunsAreBitIdenticalWithSeededNoise) {
  const std::string noisy =
      "observations:\n"
      "  - {term: base_lin_vel, noise: 0.1}\n"
      "  - {term: base_ang_vel, noise: 0.2}\n"
      "  - {term: projected_gravity, noise: 0.05}\n"
      "  - {term: velocity_command}\n"
      "  - {term: joint_pos, noise: 0.01}\n"
      "  - {term: joint_vel, noise: 1.5}\n"
      "  - {term: last_action}\n"
      "seed: 11\n"
      "commands: [{t: 0, vx: 0.5}]\n";
  PolicyController *pa = nullptr, *pb = nullptr;
  Simulation a = PolicySim("../tests/control/fixtures/mlp_48x12.onnx", noisy, &pa);
  Simulation b = PolicySim("../tests/control/fixtures/mlp_48x12.onnx", noisy, &pb);
  EXPECT_TRUE(quadruped_test::StepInLockstep(a, b, 400));
  EXPECT_EQ(pa->last_observation(), pb->last_observation());
  // and the noise is on: the same run with another seed differs
  PolicyController* pc = nullptr;
  std::string other = noisy;
  other.replace(other.find("seed: 11"), 8, "seed: 12");
  Simulation c = PolicySim("../tests/control/fixtures/mlp_48x12.onnx", other, &pc);
  for (int i = 0; i < 400; ++i) c.Step();
  EXPECT_NE(pa->last_observation(), pc->last_observation());
}

}  // namespace
}  // namespace penumbra
