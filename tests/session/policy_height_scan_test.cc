// the policy controller's height_scan term in a loaded world: the session hands it the
// static scene's terrain ray caster (session/static_terrain_ray_caster.h), whose vertical
// rays hit a 0.1 m step in front of the quadruped and the floor elsewhere, not the robot.

#include <gtest/gtest.h>

#include <string>

#include "common/temp_dir.h"
#include "penumbra/control/policy_controller.h"
#include "penumbra/session/session.h"

namespace penumbra {
namespace {

TEST(PolicyHeightScan, RaysHitTheStaticTerrainNotTheRobot) {
  penumbra::testing::TempDir dir;
  // a floor and a 0.1 m high step from x = 0.25 to 1.05 (a box centred at 0.65)
  dir.Write("terrain.xml",
            "<mujoco><worldbody>\n"
            "  <geom name=\"floor\" type=\"plane\" size=\"0 0 0.05\"/>\n"
            "  <geom name=\"step\" type=\"box\" pos=\"0.65 0 0.05\" size=\"0.4 1 0.05\"/>\n"
            "</worldbody></mujoco>\n");
  const std::string world = dir.Write(
      "world.yaml",
      "robots:\n"
      "  - name: dog\n"
      "    file: " PENUMBRA_SOURCE_DIR
      "/worlds/models/quadruped.xml\n"
      "    controller:\n"
      "      type: policy\n"
      "      model: " PENUMBRA_SOURCE_DIR
      "/tests/control/fixtures/gemm_15x12.onnx\n"
      "      base_body: trunk\n"
      "      joints: [FR_hip, FR_thigh, FR_calf, FL_hip, FL_thigh, FL_calf,\n"
      "               RR_hip, RR_thigh, RR_calf, RL_hip, RL_thigh, RL_calf]\n"
      "      observations:\n"
      "        - {term: height_scan, size_m: [1.4, 0], resolution_m: 0.1, offset_m: 0.5}\n"
      "      action: {scale: 0, kp: 20, kd: 0.5}\n"
      "models:\n"
      "  - {name: terrain, file: terrain.xml}\n");
  SessionOptions options;
  options.build_renderer = false;
  Session session(LoadWorldFile(world), options);
  Simulation& sim = session.sim();
  auto* policy = dynamic_cast<PolicyController*>(&sim.mutable_controller(0));
  ASSERT_NE(policy, nullptr);
  ASSERT_TRUE(policy->needs_terrain_ray_caster());
  // the first step runs the policy on the state before it
  const double z = sim.Snapshot().X_WB[sim.scene().FindBody("dog/trunk")].translation().z();
  sim.Step();
  const std::vector<float>& o = policy->last_observation();
  ASSERT_EQ(o.size(), 15u);  // x = -0.7 .. 0.7 every 0.1 m, one row
  // the trunk origin stands 0.285 m over the floor (the model's qpos0); value =
  // z_base - z_hit - 0.5: -0.215 over the floor, -0.315 over the step (x >= 0.3 here)
  for (int i = 0; i < 15; ++i) {
    const double x = -0.7 + 0.1 * i;
    const double hit = x > 0.25 ? 0.1 : 0.0;
    EXPECT_NEAR(o[i], z - hit - 0.5, 1e-5) << "x = " << x;  // float32 rays from 20 m up
  }
  EXPECT_NEAR(z, 0.285, 0.01);
}

}  // namespace
}  // namespace penumbra
