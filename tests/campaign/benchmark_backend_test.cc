// `penumbra benchmark --backend B` reaches every job: the Slurm array's command line carries
// `--backend B` (quoted), and none when no backend was given (campaign/benchmark_runner.h).

#include <gtest/gtest.h>

#include <string>

#include "common/temp_dir.h"
#include "penumbra/campaign/benchmark_runner.h"

namespace penumbra {
namespace {

TEST(BenchmarkBackend, SlurmTasksGetTheBackendFlag) {
  testing::TempDir dir;
  BenchmarkSpec spec;
  spec.name = "t";
  spec.file = (dir.path() / "spec.yaml").string();
  spec.render_threads = 1;
  const std::string out = (dir.path() / "out").string();
  const std::string with = SlurmBatchScript(spec, out, "/bin/echo", {0, 1}, "cuda");
  EXPECT_NE(with.find("--job \"$SLURM_ARRAY_TASK_ID\" --quiet --backend 'cuda'\n"),
            std::string::npos)
      << with;
  const std::string without = SlurmBatchScript(spec, out, "/bin/echo", {0, 1});
  EXPECT_EQ(without.find("--backend"), std::string::npos) << without;
  EXPECT_NE(without.find("--quiet\n"), std::string::npos) << without;
}

}  // namespace
}  // namespace penumbra
