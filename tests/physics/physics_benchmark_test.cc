// the physics benchmark runs its loops over the same number of steps, and the memory
// comparison's bare loop and peak reading work (no timing or size assertions: measurements
// never decide pass/fail).

#include "penumbra/physics/physics_benchmark.h"

#include <gtest/gtest.h>

#include <fstream>

#include "common/temp_dir.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

TEST(PhysicsBenchmark, RunsBothLoopsForTheRequestedSimTime) {
  const std::string path = penumbra::testing::ProcessTempDir() + "/bench_model.xml";
  std::ofstream(path) << R"(<mujoco><option timestep="0.005"/><worldbody>
    <geom type="plane" size="2 2 0.1"/>
    <body pos="0 0 0.3"><freejoint/><geom type="box" size=".1 .1 .1"/></body>
  </worldbody></mujoco>)";
  const PhysicsBenchResult r = BenchmarkPhysics(path, 1.0);
  EXPECT_EQ(r.steps, 200);
  EXPECT_GT(r.penumbra_steps_per_sec, 0);
  EXPECT_GT(r.bare_steps_per_sec, 0);
  EXPECT_GT(r.step_only_steps_per_sec, 0);
  EXPECT_NEAR(r.ratio, r.penumbra_steps_per_sec / r.bare_steps_per_sec, 1e-12);
  EXPECT_NEAR(r.step_only_ratio, r.step_only_steps_per_sec / r.bare_steps_per_sec, 1e-12);
  EXPECT_THROW(BenchmarkPhysics(path, 0), ConfigError);
  EXPECT_THROW(BenchmarkPhysics("/nonexistent.xml", 1), ConfigError);

  EXPECT_EQ(RunBareMujocoLoop(path, 1.0), 200);
  EXPECT_THROW(RunBareMujocoLoop(path, -1), ConfigError);
  EXPECT_THROW(RunBareMujocoLoop("/nonexistent.xml", 1), ConfigError);
  // this test process has touched at least its own code and MuJoCo's
  EXPECT_GT(PeakResidentKiB(), 1024);
}

}  // namespace
}  // namespace penumbra
