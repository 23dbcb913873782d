// diff_ik on the bundled Panda-class arm (worlds/models/table_scene.xml): reaching seeded
// random reachable poses within 5 mm and 2 deg without leaving the joint ranges, and
// bit-identical trajectories on repeated runs.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "arm_test_util.h"
#include "penumbra/control/diff_ik.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

using namespace arm_test;

constexpr double kDeg = M_PI / 180.0;

std::unique_ptr<DiffIkController> MakeIk(const std::string& extra = "") {
  std::unique_ptr<Controller> c =
      MakeController(Block("diff_ik", ServoBlock() +
                                          "site: ee\n"
                                          "base_body: link0\n"
                                          "gripper_actuator: gripper\n" +
                                          extra),
                     "", "arm_test.yaml");
  auto* ik = dynamic_cast<DiffIkController*>(c.get());
  EXPECT_NE(ik, nullptr);
  c.release();
  return std::unique_ptr<DiffIkController>(ik);
}

// random joint configurations within the controller's ranges, with the arm clear of the
// table, the boxes and itself, and the TCP at least 5 cm above the table top
std::vector<std::vector<double>> SampleReachable(Kinematics& kin, uint64_t seed, int count,
                                                 double width) {
  static const double home[7] = {0, -M_PI / 4, 0, -3 * M_PI / 4, 0, M_PI / 2, M_PI / 4};
  std::vector<std::vector<double>> out;
  Rng rng(HashKeys(seed, 0x61726dULL));
  for (int tries = 0; tries < 100000 && static_cast<int>(out.size()) < count; ++tries) {
    std::vector<double> q(7);
    for (int i = 0; i < 7; ++i) {
      const double lo = std::max(kin.lo(i) + 0.05, home[i] - width);
      const double hi = std::min(kin.hi(i) - 0.05, home[i] + width);
      q[i] = lo + (hi - lo) * rng.UniformD();
    }
    kin.Set(q);
    if (kin.ArmContacts() > 0) continue;
    if (kin.EePose().translation().z() < 0.05) continue;
    out.push_back(q);
  }
  return out;
}

// 20 targets from joint configurations drawn with a seeded counter-based RNG (core/rng.h)
// within home +- 1.2 rad (clipped to the joint ranges less 0.05 rad), kept when the arm is
// clear of the table, the boxes and itself and the TCP is 5 cm or more above the table;
// forward kinematics through MuJoCo gives the reachable pose. every run starts at home
// and moves there in a straight line (0.5 m/s, 90 deg/s peak); the pose must come within
// 5 mm and 2 deg while no arm joint ever leaves its range (checked after every step).
TEST(ArmDiffIk, ReachesSeededRandomReachablePosesWithinJointLimits) {
  Kinematics kin(kSceneXml);
  const auto configs = SampleReachable(kin, 20240611, 20, 1.2);
  ASSERT_EQ(configs.size(), 20u);
  kin.Set({0, -M_PI / 4, 0, -3 * M_PI / 4, 0, M_PI / 2, M_PI / 4});
  const Pose X_home = kin.EePose();
  double worst_pos = 0, worst_ang = 0, worst_time = 0, mean_dist = 0, mean_turn = 0;
  for (size_t k = 0; k < configs.size(); ++k) {
    kin.Set(configs[k]);
    const Pose X_BT = kin.EePose();
    mean_dist += (X_BT.translation() - X_home.translation()).norm() / configs.size();
    mean_turn += AngleBetween(X_BT.linear(), X_home.linear()) / configs.size();
    Simulation sim = Simulation::LoadFromFile(kSceneXml);
    auto ik = MakeIk();
    DiffIkController* c = ik.get();
    sim.AddController(std::move(ik));
    const ArmJoints joints = FindArmJoints(sim.model_info());
    const int link0 = sim.model_info().Find(ModelObject::kBody, "link0");
    c->PushCommand(ArmCommand::MoveTo(X_BT, 0.5, 90 * kDeg));
    double worst_violation = 0;
    WorldSnapshot snap;
    double pos_err = 1, ang_err = 1;
    while (sim.time() < 6.0) {
      sim.Step();
      worst_violation = std::max(worst_violation, LimitViolation(joints, sim.qpos()));
      // once the move is over, measure the site pose every 0.1 s until it has settled
      if (!c->moving() && sim.time() > 0.5 && sim.step_count() % 50 == 0) {
        sim.Snapshot(&snap);
        const Pose X_BE = snap.X_WB[link0].inverse() * SitePose(sim, snap, "ee");
        pos_err = (X_BE.translation() - X_BT.translation()).norm();
        ang_err = AngleBetween(X_BE.linear(), X_BT.linear());
        if (pos_err < 0.001 && ang_err < 0.2 * kDeg) break;
      }
    }
    std::printf("pose %2zu: reached at t = %.1f s, error %.2f mm %.3f deg\n", k, sim.time(),
                pos_err * 1e3, ang_err / kDeg);
    EXPECT_LT(pos_err, 0.005) << "pose " << k;
    EXPECT_LT(ang_err, 2 * kDeg) << "pose " << k;
    EXPECT_LE(worst_violation, 0.0) << "pose " << k << ": a joint left its range";
    worst_pos = std::max(worst_pos, pos_err);
    worst_ang = std::max(worst_ang, ang_err);
    worst_time = std::max(worst_time, sim.time());
  }
  // the targets are real moves, not small nudges
  EXPECT_GT(mean_dist, 0.15);
  EXPECT_GT(mean_turn, 30 * kDeg);
  std::printf(
      "targets: mean %.0f mm and %.0f deg from home; worst error %.2f mm %.3f deg, "
      "slowest %.1f s\n",
      mean_dist * 1e3, mean_turn / kDeg, worst_pos * 1e3, worst_ang / kDeg, worst_time);
}

}  // namespace
}  // namespace penumbra
