// pick and place on the bundled table scene with diff_ik driven by a world-file command
// script: the 5 cm cube is grasped, carried 0.3 m and put down on the target marker;
// two runs give bit-identical trajectories.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <thread>

#include "arm_test_util.h"
#include "penumbra/control/diff_ik.h"

namespace penumbra {
namespace {

using namespace arm_test;

// cube at (0.5, -0.15) on the table (z = 0 is the table top, the base frame is the world
// frame), target marker at (0.5, 0.15). gripper fingers open along the base y axis with
// rpy (180, 0, 0), so they close on the cube's +-y faces.
constexpr const char* kPickPlaceScript = R"(site: ee
base_body: link0
gripper_actuator: gripper
gripper_initial: open
speed_m_s: 0.3
commands:
  - {t: 0.0, move_to: {xyz: [0.5, -0.15, 0.15], rpy_deg: [180, 0, 0]}}
  - {t: 2.8, move_to: {xyz: [0.5, -0.15, 0.025]}, speed_m_s: 0.15}
  - {t: 4.6, gripper: close}
  - {t: 5.3, move_by: {xyz: [0, 0, 0.15]}, speed_m_s: 0.15}
  - {t: 7.4, move_to: {xyz: [0.5, 0.15, 0.175]}}
  - {t: 9.5, move_to: {xyz: [0.5, 0.15, 0.027]}, speed_m_s: 0.15}
  - {t: 11.6, gripper: open}
  - {t: 12.2, move_by: {xyz: [0, 0, 0.15]}, speed_m_s: 0.15}
)";

// reads the finger touch sensors at every step (writes no ctrl): the Simulation exposes
// sensordata only through ControlInput
class TouchProbe final : public Controller {
 public:
  TouchProbe() : Controller(ControllerContext{}) {}
  std::string type() const override { return "touch_probe"; }
  double rate_hz() const override { return 0; }
  std::vector<NameRequirement> RequiredNames() const override {
    return {{ModelObject::kSensor, "left_pad_touch", ""},
            {ModelObject::kSensor, "right_pad_touch", ""}};
  }
  void Reset() override {}  // no memory: reads the current sensors
  void Compute(const ControlInput& input, std::span<double>) override {
    left_ = input.sensordata()[left_adr_];
    right_ = input.sensordata()[right_adr_];
  }
  double left() const { return left_; }
  double right() const { return right_; }

 protected:
  void OnInitialize(const ModelInfo& m, const std::vector<int>& ids) override {
    left_adr_ = m.sensors[ids[0]].adr;
    right_adr_ = m.sensors[ids[1]].adr;
  }

 private:
  int left_adr_ = 0, right_adr_ = 0;
  double left_ = 0, right_ = 0;
};

struct PickPlaceRun {
  std::vector<double> trajectory;  // qpos after every step
  Eigen::Vector3d cube_start, cube_end;
  double cube_tilt_end = 0;            // rad
  double max_cube_z_carried = 0;       // m, while carried (7.4 s .. 9.5 s)
  double min_cube_z_carried = 1;       // m
  double min_touch_carried = 1e9;      // N, smaller of the two pads while carried
  double max_touch_after_release = 0;  // N, after the gripper opened and lifted
  double worst_limit_violation = 0;    // rad
};

PickPlaceRun RunPickPlace() {
  PickPlaceRun r;
  Simulation sim = Simulation::LoadFromFile(kSceneXml);
  sim.AddController(
      MakeController(Block("diff_ik", ServoBlock() + kPickPlaceScript), "", "arm_pick_place.yaml"));
  const ModelInfo& m = sim.model_info();
  const int cube = m.Find(ModelObject::kBody, "cube");
  const int cube_joint = m.Find(ModelObject::kJoint, "cube_free");
  auto probe_owned = std::make_unique<TouchProbe>();
  const TouchProbe* probe = probe_owned.get();
  sim.AddController(std::move(probe_owned));
  const ArmJoints joints = FindArmJoints(m);
  const int qa = m.joints[cube_joint].qpos_adr;
  r.cube_start = Eigen::Vector3d(sim.qpos()[qa], sim.qpos()[qa + 1], sim.qpos()[qa + 2]);
  WorldSnapshot snap;
  while (sim.time() < 14.2) {
    sim.Step();
    const auto q = sim.qpos();
    r.trajectory.insert(r.trajectory.end(), q.begin(), q.end());
    r.worst_limit_violation = std::max(r.worst_limit_violation, LimitViolation(joints, q));
    const double t = sim.time();
    if (t > 7.4 && t < 9.5) {
      sim.Snapshot(&snap);
      const double z = snap.X_WB[cube].translation().z();
      r.max_cube_z_carried = std::max(r.max_cube_z_carried, z);
      r.min_cube_z_carried = std::min(r.min_cube_z_carried, z);
      r.min_touch_carried = std::min({r.min_touch_carried, probe->left(), probe->right()});
    }
    if (t > 12.4)
      r.max_touch_after_release =
          std::max({r.max_touch_after_release, probe->left(), probe->right()});
  }
  r.cube_end = Eigen::Vector3d(sim.qpos()[qa], sim.qpos()[qa + 1], sim.qpos()[qa + 2]);
  const Eigen::Quaterniond quat(sim.qpos()[qa + 3], sim.qpos()[qa + 4], sim.qpos()[qa + 5],
                                sim.qpos()[qa + 6]);
  r.cube_tilt_end =
      std::acos(std::clamp((quat.toRotationMatrix() * Eigen::Vector3d::UnitZ()).z(), -1.0, 1.0));
  return r;
}

TEST(ArmPickPlace, CarriesTheCubeToTheTargetMarker) {
  const PickPlaceRun r = RunPickPlace();
  const Eigen::Vector3d target(0.5, 0.15, 0.025);
  std::printf(
      "cube start (%.4f, %.4f, %.4f), end (%.4f, %.4f, %.4f), %.1f mm from the target, "
      "tilt %.2f deg; carried at z %.3f .. %.3f m, pad forces >= %.1f N\n",
      r.cube_start.x(), r.cube_start.y(), r.cube_start.z(), r.cube_end.x(), r.cube_end.y(),
      r.cube_end.z(), (r.cube_end - target).head<2>().norm() * 1e3, r.cube_tilt_end * 180 / M_PI,
      r.min_cube_z_carried, r.max_cube_z_carried, r.min_touch_carried);
  EXPECT_NEAR((r.cube_end - r.cube_start).head<2>().norm(), 0.3, 0.02);
  EXPECT_LT((r.cube_end - target).head<2>().norm(), 0.02);
  EXPECT_NEAR(r.cube_end.z(), 0.025, 0.003);  // resting on the table
  EXPECT_LT(r.cube_tilt_end, 5 * M_PI / 180);
  EXPECT_GT(r.min_cube_z_carried, 0.1);  // lifted clear of the table while carried
  // both finger pads press on the cube all the way (and the cube's 1 N weight hangs on
  // friction), and nothing touches them once the gripper has let go
  EXPECT_GT(r.min_touch_carried, 5.0);
  EXPECT_EQ(r.max_touch_after_release, 0.0);
  EXPECT_LE(r.worst_limit_violation, 0.0);
}

TEST(ArmPickPlace, TwoRunsAreBitIdentical) {
  const PickPlaceRun a = RunPickPlace();
  const PickPlaceRun b = RunPickPlace();
  ASSERT_EQ(a.trajectory.size(), b.trajectory.size());
  ASSERT_GT(a.trajectory.size(), 7000u * 30u);
  EXPECT_EQ(
      std::memcmp(a.trajectory.data(), b.trajectory.data(), a.trajectory.size() * sizeof(double)),
      0);
}

// the programmatic API: the script's commands pushed from another thread while the
// simulation steps, each with its due time 1 s later than in the script, reproduce the
// scripted trajectory shifted by 1 s (the arm holds still at home until then)
TEST(ArmPickPlace, CommandsPushedFromAnotherThreadActAtTheirTimes) {
  Simulation scripted = Simulation::LoadFromFile(kSceneXml);
  std::string shifted = kPickPlaceScript;
  for (const char* t : {"12.2", "11.6", "9.5", "7.4", "5.3", "4.6", "2.8", "0.0"}) {
    const std::string from = std::string("{t: ") + t + ",";
    const size_t at = shifted.find(from);
    ASSERT_NE(at, std::string::npos) << t;
    char buf[32];
    std::snprintf(buf, sizeof(buf), "{t: %.1f,", std::atof(t) + 1.0);
    shifted.replace(at, from.size(), buf);
  }
  scripted.AddController(
      MakeController(Block("diff_ik", ServoBlock() + shifted), "", "arm_pick_place.yaml"));

  Simulation driven = Simulation::LoadFromFile(kSceneXml);
  std::string no_script = kPickPlaceScript;
  no_script.erase(no_script.find("commands:"));
  std::unique_ptr<Controller> owned =
      MakeController(Block("diff_ik", ServoBlock() + no_script), "", "arm_pick_place.yaml");
  auto* ik = dynamic_cast<DiffIkController*>(owned.get());
  ASSERT_NE(ik, nullptr);
  driven.AddController(std::move(owned));

  auto xyz = [](double x, double y, double z, bool keep_orientation) {
    Pose X = PoseFromXyzRpyDeg(Eigen::Vector3d(x, y, z), Eigen::Vector3d(180, 0, 0));
    ArmCommand c = ArmCommand::MoveTo(X);
    c.has_orientation = !keep_orientation;
    return c;
  };
  auto speed = [](ArmCommand c, double v) {
    c.speed_m_s = v;
    return c;
  };
  const Pose up = PoseFromXyzRpyDeg(Eigen::Vector3d(0, 0, 0.15), Eigen::Vector3d::Zero());
  std::thread feeder([&] {
    ik->PushCommand(xyz(0.5, -0.15, 0.15, false), 1.0);
    ik->PushCommand(speed(xyz(0.5, -0.15, 0.025, true), 0.15), 3.8);
    ik->PushCommand(ArmCommand::Gripper(ArmCommand::GripperAction::kClose), 5.6);
    ik->PushCommand(ArmCommand::MoveBy(up, 0.15), 6.3);
    ik->PushCommand(xyz(0.5, 0.15, 0.175, true), 8.4);
    ik->PushCommand(speed(xyz(0.5, 0.15, 0.027, true), 0.15), 10.5);
    ik->PushCommand(ArmCommand::Gripper(ArmCommand::GripperAction::kOpen), 12.6);
    ik->PushCommand(ArmCommand::MoveBy(up, 0.15), 13.2);
  });
  // the feeder runs while the first 0.5 s are simulated; every command is due later
  while (driven.time() < 0.5) driven.Step();
  feeder.join();
  while (driven.time() < 15.2) {
    driven.Step();
    scripted.Step();
  }
  while (scripted.time() < driven.time()) scripted.Step();
  ASSERT_EQ(scripted.step_count(), driven.step_count());
  EXPECT_EQ(std::memcmp(scripted.qpos().data(), driven.qpos().data(),
                        scripted.qpos().size() * sizeof(double)),
            0);
  const ModelInfo& m = driven.model_info();
  const int qa = m.joints[m.Find(ModelObject::kJoint, "cube_free")].qpos_adr;
  EXPECT_NEAR(driven.qpos()[qa + 1], 0.15, 0.02);  // the cube was moved, too
}

}  // namespace
}  // namespace penumbra
