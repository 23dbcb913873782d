// the nav harness's judgement of how an episode's run ended (campaign/nav_job.h
// NavRunDelivered): a run that had reached its duration and written run.json when the
// harness's SIGTERM came, and died of that signal with its handler already gone, delivered its
// episode (the warehouse aisle_12m `major` seed-3 episode of the nav benchmark was marked
// run_failed so, docs/benchmarks.md); a run ended by a signal before run.json did not.

#include "penumbra/campaign/nav_job.h"

#include <gtest/gtest.h>
#include <signal.h>

#include <filesystem>

#include "common/temp_dir.h"
#include "penumbra/campaign/child_process.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

TEST(NavJob, RunKilledBySigtermAfterItsOutputsDeliveredItsEpisode) {
  const testing::TempDir dir;
  const fs::path run_dir = dir.path() / "run";
  // a real run to its end: exit 0 and run.json
  ChildProcess run({PENUMBRA_BINARY, "run",
                    (fs::path(PENUMBRA_SOURCE_DIR) / "tests/campaign/data/nav_wall.yaml").string(),
                    "--out", run_dir.string(), "--force", "--quiet", "--duration", "0.02"},
                   dir.path().string(), (dir.path() / "run.log").string(),
                   (dir.path() / "run.log").string());
  ASSERT_TRUE(run.WaitFor(120)) << "the run did not end";
  ASSERT_EQ(run.exit_code(), 0) << run.Describe();
  ASSERT_TRUE(fs::is_regular_file(run_dir / "run.json"));
  EXPECT_TRUE(NavRunDelivered(run.exit_code(), run.signal(), run_dir.string()));

  // a process ended by SIGTERM's default action, as the run is once past its end
  ChildProcess killed({"sleep", "30"}, dir.path().string(), (dir.path() / "sleep.log").string(),
                      (dir.path() / "sleep.log").string(), /*search_path=*/true);
  killed.TerminateAndWait(5);
  ASSERT_EQ(killed.signal(), SIGTERM) << killed.Describe();
  // with run.json written: the episode's outputs are whole (main judged it run_failed)
  EXPECT_TRUE(NavRunDelivered(killed.exit_code(), killed.signal(), run_dir.string()));
  // the run's handler ended it: outputs written
  EXPECT_TRUE(NavRunDelivered(143, 0, run_dir.string()));
  EXPECT_TRUE(NavRunDelivered(130, 0, run_dir.string()));
  // no run.json: killed before its outputs were whole
  fs::remove(run_dir / "run.json");
  EXPECT_FALSE(NavRunDelivered(killed.exit_code(), killed.signal(), run_dir.string()));
  // a crash or another signal is a failure whatever it wrote
  EXPECT_FALSE(NavRunDelivered(1, 0, run_dir.string()));
  EXPECT_FALSE(NavRunDelivered(-1, SIGKILL, run_dir.string()));
  EXPECT_FALSE(NavRunDelivered(-1, SIGSEGV, run_dir.string()));
}

}  // namespace
}  // namespace penumbra
