#include "penumbra/output/trajectory_sink.h"

#include <gtest/gtest.h>

#include "common/run_loop.h"
#include "common/temp_dir.h"
#include "penumbra/pipeline/sim_loop.h"

namespace penumbra {
namespace {

using testing::ReadAll;
using testing::TempDir;

// steps of 0.1 s; qpos = {step, -step / 3}
class Steps : public Source {
 public:
  int64_t step() const override { return step_; }
  double time_sec() const override { return 0.1 * static_cast<double>(step_); }
  std::shared_ptr<const WorldSnapshot> Snapshot(SnapshotContent) override {
    auto s = std::make_shared<WorldSnapshot>();
    s->step = step_;
    s->time_sec = time_sec();
    s->qpos = {static_cast<double>(step_), -static_cast<double>(step_) / 3.0};
    return s;
  }
  bool Advance() override {
    ++step_;
    return true;
  }

 private:
  int64_t step_ = 0;
};

TEST(TrajectorySinkTest, OneRowPerStepAfterTheFirstWithFullPrecision) {
  TempDir dir;
  Steps source;
  TrajectorySink sink(dir.path() / "trajectory.csv", 2);
  const LoopFinish f = testing::RunLoop(&source, {&sink}, 0.3);
  ASSERT_FALSE(f.error);
  EXPECT_EQ(ReadAll(dir.path() / "trajectory.csv"),
            "step,time_sec,qpos0,qpos1\n"
            "1,0.10000000000000001,1,-0.33333333333333331\n"
            "2,0.20000000000000001,2,-0.66666666666666663\n"
            "3,0.30000000000000004,3,-1\n");
}

}  // namespace
}  // namespace penumbra
