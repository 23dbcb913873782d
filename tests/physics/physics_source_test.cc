#include "penumbra/physics/physics_source.h"

#include <gtest/gtest.h>

#include <vector>

#include "common/run_loop.h"
#include "penumbra/pipeline/sim_loop.h"

namespace penumbra {
namespace {

// a box falling onto a plane: contacts and a free joint (nq = 7)
constexpr const char* kBoxXml = R"(<mujoco>
  <option timestep="0.01"/>
  <worldbody>
    <geom type="plane" size="5 5 0.1"/>
    <body name="box" pos="0 0 0.3"><freejoint/><geom type="box" size="0.1 0.1 0.1"/></body>
  </worldbody>
</mujoco>)";

// records the snapshots of every step, asking for `content`
class Collect : public Sink {
 public:
  explicit Collect(SnapshotContent content) : content_(content) {}
  SnapshotContent Wants(int64_t, double) override { return content_; }
  void OnSnapshot(const std::shared_ptr<const WorldSnapshot>& s) override { got.push_back(s); }
  std::vector<std::shared_ptr<const WorldSnapshot>> got;

 private:
  SnapshotContent content_;
};

TEST(PhysicsSourceTest, StepsTheSimulationAndHandsOutItsStatePerStep) {
  Simulation sim = Simulation::LoadFromString(kBoxXml);
  Simulation reference = Simulation::LoadFromString(kBoxXml);
  PhysicsSource source(&sim);
  Collect state(SnapshotContent::kState);
  const LoopFinish f = testing::RunLoop(&source, {&state}, 0.5);
  ASSERT_FALSE(f.error);
  EXPECT_EQ(f.step, 50);
  ASSERT_EQ(state.got.size(), 51u);
  // the same trajectory as stepping the simulation by hand, bit for bit
  for (size_t i = 0; i < state.got.size(); ++i) {
    const WorldSnapshot& s = *state.got[i];
    EXPECT_EQ(s.step, static_cast<int64_t>(i));
    EXPECT_EQ(s.time_sec, reference.time());
    EXPECT_EQ(s.qpos, std::vector<double>(reference.qpos().begin(), reference.qpos().end()));
    EXPECT_EQ(s.qvel, std::vector<double>(reference.qvel().begin(), reference.qvel().end()));
    EXPECT_TRUE(s.X_WB.empty()) << "kState holds no poses";
    reference.Step();
  }
  EXPECT_GT(source.busy_sec(), 0.0);
}

TEST(PhysicsSourceTest, FullSnapshotsMatchTheSimulationsOwn) {
  Simulation sim = Simulation::LoadFromString(kBoxXml);
  Simulation reference = Simulation::LoadFromString(kBoxXml);
  PhysicsSource source(&sim);
  for (int i = 0; i < 30; ++i) {
    source.Advance();
    reference.Step();
  }
  const auto full = source.Snapshot(SnapshotContent::kFull);
  const WorldSnapshot want = reference.Snapshot(Simulation::SnapshotContent::kFull);
  EXPECT_EQ(full->step, 30);
  ASSERT_EQ(full->X_WB.size(), want.X_WB.size());
  EXPECT_TRUE(full->X_WB[1].isApprox(want.X_WB[1], 0.0));
  EXPECT_EQ(full->sensordata, want.sensordata);
  EXPECT_EQ(full->contacts.size(), want.contacts.size());
  EXPECT_FALSE(full->contacts.empty()) << "the box rests on the plane";
  const auto poses = source.Snapshot(SnapshotContent::kPoses);
  EXPECT_TRUE(poses->X_WB[1].isApprox(want.X_WB[1], 0.0));
  EXPECT_TRUE(poses->contacts.empty());
}

// before_step runs before every step with the simulation about to step: what it sets (here
// ctrl-like xfrc_applied) is in the step, and returning false ends the source there
TEST(PhysicsSourceTest, BeforeStepRunsBeforeEachStepAndCanEndTheSource) {
  Simulation sim = Simulation::LoadFromString(kBoxXml);
  std::vector<int64_t> called_at;
  PhysicsSourceOptions options;
  options.before_step = [&](Simulation& s) {
    called_at.push_back(s.step_count());
    return s.step_count() < 20;
  };
  PhysicsSource source(&sim, options);
  Collect state(SnapshotContent::kState);
  const LoopFinish f = testing::RunLoop(&source, {&state}, 0.5);
  ASSERT_FALSE(f.error);
  EXPECT_EQ(f.reason, LoopEndReason::kSourceEnded);
  EXPECT_EQ(f.step, 20);
  EXPECT_EQ(sim.step_count(), 20);
  ASSERT_EQ(called_at.size(), 21u);
  for (size_t i = 0; i < called_at.size(); ++i) EXPECT_EQ(called_at[i], static_cast<int64_t>(i));
  EXPECT_EQ(state.got.size(), 21u);
}

}  // namespace
}  // namespace penumbra
