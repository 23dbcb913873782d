// the world file's `initial_keyframe` starts one model from one of its MJCF
// keys; the other models keep their reference configuration.
#include <gtest/gtest.h>

#include <string>

#include "common/temp_dir.h"
#include "penumbra/session/session.h"

namespace penumbra {
namespace {

std::string Pendulum() {
  return "<mujoco>\n"
         "  <worldbody><body name=\"arm\" pos=\"0 0 1\">\n"
         "    <joint name=\"hinge\" type=\"hinge\" axis=\"0 1 0\" damping=\"1\"/>\n"
         "    <geom type=\"capsule\" fromto=\"0 0 0 0 0 -0.5\" size=\"0.02\"/>\n"
         "  </body></worldbody>\n"
         "  <actuator><motor name=\"m\" joint=\"hinge\"/></actuator>\n"
         "  <keyframe><key name=\"home\" qpos=\"0.7\" qvel=\"-0.25\" ctrl=\"0.5\"/></keyframe>\n"
         "</mujoco>\n";
}

TEST(InitialKeyframe, StartsOneModelFromItsKey) {
  penumbra::testing::TempDir dir;
  dir.Write("pendulum.xml", Pendulum());
  const std::string world =
      dir.Write("world.yaml",
                "models:\n"
                "  - {name: a, file: pendulum.xml, initial_keyframe: home}\n"
                "  - {name: b, file: pendulum.xml, pose: {xyz: [2, 0, 0]}}\n");
  SessionOptions options;
  options.build_renderer = false;
  Session session(LoadWorldFile(world), options);
  const Simulation& sim = session.sim();
  const ModelInfo& info = sim.model_info();
  const SimState s = sim.GetState();
  const JointInfo& a = info.joints[info.Find(ModelObject::kJoint, "a/hinge")];
  const JointInfo& b = info.joints[info.Find(ModelObject::kJoint, "b/hinge")];
  EXPECT_EQ(s.qpos[a.qpos_adr], 0.7);
  EXPECT_EQ(s.qvel[a.dof_adr], -0.25);
  EXPECT_EQ(s.ctrl[info.Find(ModelObject::kActuator, "a/m")], 0.5);
  EXPECT_EQ(s.qpos[b.qpos_adr], 0.0);
  EXPECT_EQ(s.qvel[b.dof_adr], 0.0);
  EXPECT_EQ(s.ctrl[info.Find(ModelObject::kActuator, "b/m")], 0.0);
  // the derived state follows: the snapshot shows a's arm rotated, b's not
  const WorldSnapshot snap = sim.Snapshot();
  const auto& names = info.body_names;
  const auto body = [&](const std::string& n) {
    return static_cast<int>(std::find(names.begin(), names.end(), n) - names.begin());
  };
  const Eigen::Matrix3d R_a = snap.X_WB[body("a/arm")].linear();
  EXPECT_NEAR(R_a(0, 2), std::sin(0.7), 1e-12);
  EXPECT_NEAR(snap.X_WB[body("b/arm")].linear()(0, 2), 0.0, 1e-12);
}

}  // namespace
}  // namespace penumbra
