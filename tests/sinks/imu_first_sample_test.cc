// the first IMU sample of a robot standing under its controller read the free fall
// of a robot with ctrl 0 (about 0 instead of gravity): the first snapshot of a run now comes
// after the controllers' first update (PhysicsSource, Simulation::RunDueControllers), and the
// trajectory is the same bit for bit.
#include <gtest/gtest.h>

#include <string>

#include "common/temp_dir.h"
#include "penumbra/physics/physics_source.h"
#include "penumbra/session/session.h"

namespace penumbra {
namespace {

// the bundled Panda-class arm held where it starts by diff_ik with gravity compensation (no
// commands: it holds the first pose; the gripper held open as it starts), an ideal IMU on
// its wrist
std::string HeldArmWorld() {
  return "physics: {timestep_sec: 0.002}\n"
         "robots:\n"
         "  - name: arm\n"
         "    file: " +
         std::string(PENUMBRA_SOURCE_DIR) +
         "/worlds/models/arm.xml\n"
         "    controller:\n"
         "      type: diff_ik\n"
         "      site: ee\n"
         "      base_body: link0\n"
         "      joints: [joint1, joint2, joint3, joint4, joint5, joint6, joint7]\n"
         "      actuators: [actuator1, actuator2, actuator3, actuator4, actuator5, actuator6, "
         "actuator7]\n"
         "      output: torque\n"
         "      gravity_compensation: true\n"
         "      gripper_actuator: gripper\n"
         "      gripper_initial: open\n"
         "    sensors:\n"
         "      - {name: wrist_imu, type: imu, body: link7, preset: ideal}\n";
}

Eigen::Vector3d WristAccel(const Simulation& sim, const WorldSnapshot& s) {
  const int id = sim.model_info().Find(ModelObject::kSensor, "penumbra_imu/wrist_imu/accel");
  EXPECT_GE(id, 0);
  const int adr = sim.model_info().sensors.at(id).adr;
  return Eigen::Vector3d(s.sensordata.at(adr), s.sensordata.at(adr + 1), s.sensordata.at(adr + 2));
}

TEST(PhysicsSourceStart, FirstImuSampleOfARobotAtRestReadsGravity) {
  penumbra::testing::TempDir dir;
  const std::string world = dir.Write("world.yaml", HeldArmWorld());
  SessionOptions options;
  options.build_renderer = false;
  Session session(LoadWorldFile(world), options);
  Session reference(LoadWorldFile(world), options);
  PhysicsSource source(&session.sim());
  const auto first = source.Snapshot(SnapshotContent::kFull);
  const Eigen::Vector3d a0 = WristAccel(session.sim(), *first);
  std::printf("[ measured ] first wrist IMU sample |a| = %.6f m/s^2\n", a0.norm());
  EXPECT_NEAR(a0.norm(), 9.81, 0.01 * 9.81);
  // the controllers' first update is in the first snapshot
  EXPECT_NE(first->ctrl, std::vector<double>(first->ctrl.size(), 0.0));
  // and is not run twice: the same trajectory as plain steps, bit for bit
  for (int i = 0; i < 50; ++i) {
    ASSERT_TRUE(source.Advance());
    reference.sim().Step();
  }
  const auto a = source.Snapshot(SnapshotContent::kState);
  const SimState b = reference.sim().GetState();
  EXPECT_EQ(a->qpos, b.qpos);
  EXPECT_EQ(a->qvel, b.qvel);
  EXPECT_EQ(a->ctrl, b.ctrl);
  // held: still about gravity after 0.1 s
  EXPECT_NEAR(WristAccel(session.sim(), *source.Snapshot(SnapshotContent::kFull)).norm(), 9.81,
              0.01 * 9.81);
}

}  // namespace
}  // namespace penumbra
