// the acceptance test of the SLAM benchmark: a short spec (one world, 2 conditions, 2
// trials, OpenCV RGB-D odometry) through the real `penumbra benchmark` (recording, local
// worker processes, replays, TUM export, methods as processes, evaluation, report).

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <sstream>

#include "common/temp_dir.h"
#include "penumbra/campaign/benchmark_report.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;
using testing::ReadAll;
using testing::TempDir;

std::vector<std::vector<std::string>> ParseCsv(const std::string& text) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::string cur;
    bool quoted = false;
    for (char c : line) {
      if (c == '"')
        quoted = !quoted;
      else if (c == ',' && !quoted) {
        f.push_back(cur);
        cur.clear();
      } else
        cur += c;
    }
    f.push_back(cur);
    rows.push_back(f);
  }
  return rows;
}

int RunBenchmarkCli(const std::string& args) {
  const int status = std::system((std::string(PENUMBRA_BINARY) + " benchmark " + args).c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string ShortSpec() {
  return std::string("name: short\nworlds:\n  - name: room\n    file: ") + PENUMBRA_SOURCE_DIR +
         "/worlds/default.yaml\n    duration_sec: 1.5\n"
         "    camera: {name: cam, attach: go1/camera_mount, width: 160, height: 120, fovy_deg: 70, "
         "rate_hz: 10}\n"
         "conditions: [none, major]\ntrials: 2\nmethods:\n"
         "  - {name: rgbd, bundled: opencv_rgbd}\n"
         "  - {name: crash, command: \"sh -c 'kill -SEGV $$'\"}\n"
         "  - {name: silent, command: \"true\"}\n"
         "  - {name: slow, command: \"sleep 20\", timeout_sec: 0.5}\n"
         "render: {threads: 1}\nworkers: 2\n";
}

TEST(BenchmarkEndToEnd, ShortSlamSpecRowsStatusesAndSharedGroundTruth) {
  TempDir dir;
  const std::string spec = dir.Write("spec.yaml", ShortSpec());
  const fs::path out = dir.path() / "out";
  ASSERT_EQ(RunBenchmarkCli(spec + " --out " + out.string() + " --quiet 2>" +
                            (dir.path() / "err.txt").string()),
            0)
      << ReadAll(dir.path() / "err.txt");
  const auto rows = ParseCsv(ReadAll(out / "results.csv"));
  ASSERT_EQ(rows.size(), 1u + 2 * 2 * 4);
  EXPECT_EQ(rows[0], BenchmarkCsvColumns());
  std::map<std::string, size_t> col;
  for (size_t i = 0; i < rows[0].size(); ++i) col[rows[0][i]] = i;
  for (size_t r = 1; r < rows.size(); ++r) {
    const auto& row = rows[r];
    ASSERT_EQ(row.size(), rows[0].size());
    const std::string method = row[col["method"]], status = row[col["status"]];
    EXPECT_EQ(row[col["frames"]], "16") << "1.5 s at 10 Hz, frames at 0 .. 1.5 s";
    if (method == "rgbd" && row[col["condition"]] == "major" && status != "ok") {
      // major adversity may break the odometry: recorded as such, never dropped
      EXPECT_TRUE(status == "failed" || status == "lost") << status;
      EXPECT_EQ(row[col["ate_rmse_m"]], "");
    } else if (method == "rgbd") {
      ASSERT_EQ(status, "ok") << row[col["detail"]];
      const double ate = std::stod(row[col["ate_rmse_m"]]);
      EXPECT_GT(ate, 0);
      if (row[col["condition"]] == "none") {
        EXPECT_LT(ate, 0.05) << "frame-to-frame odometry over 0.7 m of trot";
      }
      const double tracked = std::stod(row[col["tracked_fraction"]]);
      EXPECT_GT(tracked, 0);
      EXPECT_LE(tracked, 1);
    } else if (method == "crash") {
      EXPECT_EQ(status, "failed");
      EXPECT_EQ(row[col["detail"]], "signal 11 (SIGSEGV)");
      EXPECT_EQ(row[col["ate_rmse_m"]], "");
    } else if (method == "silent") {
      EXPECT_EQ(status, "no_output");
    } else {
      EXPECT_EQ(status, "timeout");
    }
  }
  // every replay saw the identical ground-truth trajectory
  const std::string gt = ReadAll(out / "jobs" / "room__none__t1" / "groundtruth.txt");
  ASSERT_GT(gt.size(), 100u);
  for (const char* job : {"room__none__t2", "room__major__t1", "room__major__t2"})
    EXPECT_EQ(ReadAll(out / "jobs" / job / "groundtruth.txt"), gt) << job;
  // the two conditions rendered different images: the estimates differ (or major lost track)
  EXPECT_NE(ReadAll(out / "jobs" / "room__none__t1" / "rgbd" / "estimate.txt"),
            ReadAll(out / "jobs" / "room__major__t1" / "rgbd" / "estimate.txt"));
  EXPECT_TRUE(fs::is_regular_file(out / "report.md"));
  EXPECT_TRUE(fs::is_regular_file(out / "plots" / "room_ate.png"));
  EXPECT_TRUE(fs::is_regular_file(out / "plots" / "traj_room__none__rgbd.png"));
  EXPECT_NE(ReadAll(out / "summary.md").find("| none | rgbd | 2/2 |"), std::string::npos)
      << ReadAll(out / "summary.md");
  EXPECT_FALSE(fs::exists(out / "jobs" / "room__none__t1" / "replay"))
      << "datasets removed unless keep_datasets";

  // a second run resumes: every job is finished, nothing runs again, the rows are the same
  const std::string before = ReadAll(out / "results.csv");
  ASSERT_EQ(RunBenchmarkCli(spec + " --out " + out.string() + " --quiet"), 0);
  EXPECT_EQ(ReadAll(out / "results.csv"), before);
  // another spec into the same folder is refused
  const std::string other = dir.Write("other.yaml", ShortSpec() + "keep_datasets: true\n");
  EXPECT_EQ(RunBenchmarkCli(other + " --out " + out.string() + " --quiet 2>/dev/null"), 2);
}

}  // namespace
}  // namespace penumbra
