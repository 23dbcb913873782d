// bundled worlds start their trot_gait robots settled: at rest on their contacts at t = 0
// (session.cc SettledState), so the first IMU sample reads gravity and the first step does not
// drop the robot; a robot's body placed in the air keeps its start; the settled start is the
// same with or without the session's controllers (what a replay builds).

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "app/child_process.h"
#include "common/temp_dir.h"
#include "penumbra/session/session.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

std::string Bundled(const std::string& name) {
  return std::string(PENUMBRA_SOURCE_DIR) + "/worlds/" + name;
}

// the linear velocities (m/s) of the robots' free joints
std::vector<Eigen::Vector3d> BaseVelocities(const Session& session) {
  const Simulation& sim = session.sim();
  std::vector<Eigen::Vector3d> out;
  for (const JointInfo& j : sim.model_info().joints) {
    bool robot = false;
    for (const ModelConfig& m : session.world().models)
      robot =
          robot || (m.is_robot && sim.model_info().body_names[j.body].rfind(m.name + "/", 0) == 0);
    if (j.type == JointInfo::Type::kFree && robot)
      out.emplace_back(sim.qvel()[j.dof_adr], sim.qvel()[j.dof_adr + 1], sim.qvel()[j.dof_adr + 2]);
  }
  return out;
}

TEST(SettledStart, TheSensorsWorldsFirstImuSampleReadsGravity) {
  testing::TempDir dir;
  const testing::ProcessResult r = testing::RunPenumbra(
      {"run", Bundled("sensors.yaml"), "--duration", "0.05", "--out", dir.str() + "/out"},
      dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream in(dir.path() / "out/imu/trunk_imu.csv");
  std::string header, row;
  ASSERT_TRUE(std::getline(in, header) && std::getline(in, row));
  std::vector<double> v;
  std::stringstream ss(row);
  for (std::string cell; std::getline(ss, cell, ',');) v.push_back(std::stod(cell));
  ASSERT_GE(v.size(), 6u) << row;
  EXPECT_EQ(v[1], 0.0) << row;  // the sample at t = 0
  const double a = std::sqrt(v[3] * v[3] + v[4] * v[4] + v[5] * v[5]);
  // gravity within 0.2 m/s^2 (2 %): the consumer_mems preset's noise and turn-on bias are
  // below 0.1 m/s^2; a robot placed unsettled read 3.6 m/s^2
  EXPECT_NEAR(a, 9.81, 0.2) << row;
}

class BundledWorldSettled : public ::testing::TestWithParam<std::string> {};

TEST_P(BundledWorldSettled, RobotsStartAtRestAndStayThereInTheFirstStep) {
  SessionOptions so;
  so.build_renderer = false;
  Session session(LoadWorldFile(Bundled(GetParam())), so);
  Simulation& sim = session.sim();
  EXPECT_EQ(sim.step_count(), 0);
  EXPECT_EQ(sim.time(), 0.0);
  // near zero: what a gait holding its stance leaves (the quadruped's base rises at 9 mm/s)
  for (const Eigen::Vector3d& v : BaseVelocities(session))
    EXPECT_LT(v.norm(), 0.02) << GetParam() << ": a base moves at " << v.transpose() << " m/s";
  // one step with the controllers: a settled robot does not drop (an unsettled quadruped's
  // base reached -0.012 m/s in the first 2 ms step, 6 m/s^2 down)
  sim.RunDueControllers();
  sim.Step();
  for (const Eigen::Vector3d& v : BaseVelocities(session))
    EXPECT_GT(v.z(), -0.004) << GetParam() << ": a base drops at " << v.z() << " m/s";
}

INSTANTIATE_TEST_SUITE_P(Worlds, BundledWorldSettled,
                         ::testing::Values("sensors.yaml", "quadruped.yaml", "default.yaml",
                                           "quadruped_target.yaml", "house.yaml"),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           std::string n = info.param.substr(0, info.param.find('.'));
                           return n;
                         });

TEST(SettledStart, TheSameWithOrWithoutTheSessionsControllers) {
  SessionOptions with, without;
  with.build_renderer = without.build_renderer = false;
  without.add_controllers = false;
  const WorldConfig world = LoadWorldFile(Bundled("quadruped.yaml"));
  const SimState a = Session(world, with).sim().GetState();
  const SimState b = Session(world, without).sim().GetState();
  ASSERT_EQ(a.qpos.size(), b.qpos.size());
  EXPECT_EQ(std::memcmp(a.qpos.data(), b.qpos.data(), a.qpos.size() * sizeof(double)), 0);
  EXPECT_EQ(a.qacc_warmstart, b.qacc_warmstart);
  EXPECT_EQ(a.qvel, b.qvel);
}

TEST(SettledStart, ARobotInTheAirKeepsItsStart) {
  // the bundled quadruped 0.5 m above the floor: it would fall, not settle
  WorldConfig world = LoadWorldFile(Bundled("quadruped.yaml"));
  for (ModelConfig& m : world.models)
    if (m.is_robot) m.pose.xyz.z() += 0.5;
  SessionOptions so;
  so.build_renderer = false;
  so.add_controllers = false;
  Session session(world, so);
  const Simulation& sim = session.sim();
  for (const JointInfo& j : sim.model_info().joints) {
    if (j.type != JointInfo::Type::kFree) continue;
    EXPECT_NEAR(sim.qpos()[j.qpos_adr + 2], 0.285 + 0.5, 1e-9);
    for (int i = 0; i < 6; ++i) EXPECT_EQ(sim.qvel()[j.dof_adr + i], 0.0);
  }
  // on the floor, the same robot settles: its base moves from where it was placed
  world = LoadWorldFile(Bundled("quadruped.yaml"));
  Session settled(world, so);
  for (const JointInfo& j : settled.sim().model_info().joints)
    if (j.type == JointInfo::Type::kFree) EXPECT_NE(settled.sim().qpos()[j.qpos_adr + 2], 0.285);
}

}  // namespace
}  // namespace penumbra
