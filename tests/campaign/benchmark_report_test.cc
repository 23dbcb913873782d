// report.md's tracking sentences and the summary's tracked / pose-fraction figures on
// constructed rows: a planted sparse trial (3 poses of 41 frames) is named, never hidden
// behind "every method tracked".
#include "penumbra/campaign/benchmark_report.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "common/temp_dir.h"
#include "penumbra/campaign/benchmark_spec.h"

namespace penumbra {
namespace {

using testing::TempDir;

BenchmarkSpec LoadSpec(TempDir& dir) {
  return LoadBenchmarkSpec(dir.Write(
      "spec.yaml", std::string("name: t\nworlds:\n  - name: room\n    file: ") +
                       PENUMBRA_SOURCE_DIR +
                       "/worlds/default.yaml\n    duration_sec: 1\n    camera: {name: cam, "
                       "attach: go1/camera_mount, width: 160, height: 120, fovy_deg: 70, "
                       "rate_hz: 10}\nconditions: [none, major]\ntrials: 2\nmethods:\n  - "
                       "{name: rgbd, bundled: opencv_rgbd}\n  - {name: icp, bundled: "
                       "opencv_icp}\n"));
}

BenchmarkRow Row(const std::string& condition, const std::string& method, int trial) {
  BenchmarkRow r;
  r.world = "room";
  r.condition = condition;
  r.method = method;
  r.trial = trial;
  r.status = "ok";
  r.frames = 41;
  r.poses = 41;
  r.ate_rmse_m = 0.2;
  r.scaled_ate_m = 0.2;
  r.coverage = 1.0;
  r.tracked_fraction = 1.0;
  r.pose_fraction = 1.0;
  return r;
}

// every (condition, method, trial) dense
std::vector<BenchmarkRow> DenseRows() {
  std::vector<BenchmarkRow> rows;
  for (const char* c : {"none", "major"})
    for (const char* m : {"rgbd", "icp"})
      for (int t = 1; t <= 2; ++t) rows.push_back(Row(c, m, t));
  return rows;
}

TEST(BenchmarkReport, DenseTrialsSayEveryMethodTrackedWithTheThreshold) {
  const std::string md = TrackingSummaryMarkdown(DenseRows());
  EXPECT_EQ(md,
            "Every method tracked at least 0.9 of the ground truth's time in every trial "
            "(8 rows).\n");
}

TEST(BenchmarkReport, APlantedSparseTrialIsNamedAndMarked) {
  // major / rgbd trial 1 kept 3 of 41 frames: tracked 0.05, its scaled ATE 5x "better"
  std::vector<BenchmarkRow> rows = DenseRows();
  BenchmarkRow& sparse = rows[4];
  ASSERT_EQ(sparse.condition + sparse.method + std::to_string(sparse.trial), "majorrgbd1");
  sparse.poses = 3;
  sparse.tracked_fraction = 0.05;
  sparse.pose_fraction = 3.0 / 41.0;
  sparse.ate_rmse_m = 1.5;
  sparse.scaled_ate_m = 0.04;
  rows[7].status = "failed";  // major / icp trial 2
  rows[7].detail = "exit 3";
  for (double* v : {&rows[7].ate_rmse_m, &rows[7].scaled_ate_m, &rows[7].tracked_fraction,
                    &rows[7].pose_fraction, &rows[7].coverage})
    *v = NAN;

  const std::string md = TrackingSummaryMarkdown(rows);
  EXPECT_EQ(md.find("Every method tracked"), std::string::npos) << md;
  EXPECT_NE(md.find("6 of 8 rows tracked at least 0.9 of the ground truth's time; 1 ran but "
                    "tracked less and 1 failed."),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("| room | major | rgbd | 1 | 0.050 | 3 / 41 | 0.073 | 1.5000 | 0.0400 |"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("| room | major | icp | 2 | failed | exit 3 |"), std::string::npos) << md;

  TempDir dir;
  const BenchmarkSpec spec = LoadSpec(dir);
  const std::vector<SummaryLine> lines = Summarize(spec, rows);
  ASSERT_EQ(lines.size(), 4u);  // none/rgbd, none/icp, major/rgbd, major/icp
  EXPECT_EQ(lines[0].tracked, 2);
  EXPECT_EQ(lines[2].ok, 2);
  EXPECT_EQ(lines[2].tracked, 1);
  EXPECT_NEAR(lines[2].pose_fraction.mean, (1.0 + 3.0 / 41.0) / 2, 1e-12);
  EXPECT_EQ(lines[3].tracked, 1);
  EXPECT_NEAR(lines[3].pose_fraction.mean, 0.5, 1e-12);  // the failed trial counts 0 poses
  const std::string table = SummaryMarkdown(spec, lines);
  // the sparse line's ATE figures carry the mark, the dense lines' do not
  EXPECT_NE(table.find("| major | rgbd | 2/2 | 1/2 | 0.8500 ± 0.9192 † | 0.1200 ± 0.1131 † |"),
            std::string::npos)
      << table;
  EXPECT_NE(table.find("| none | rgbd | 2/2 | 2/2 | 0.2000 ± 0.0000 | 0.2000 ± 0.0000 |"),
            std::string::npos)
      << table;

  // the whole report: the sentence and the sparse row in report.md, the column in results.csv
  WriteBenchmarkReport(spec, dir.path().string(), rows, 1.0);
  const std::string report = testing::ReadAll(dir.path() / "report.md");
  EXPECT_EQ(report.find("Every method tracked"), std::string::npos);
  EXPECT_NE(report.find("| room | major | rgbd | 1 | 0.050 | 3 / 41 |"), std::string::npos);
  const std::string csv = testing::ReadAll(dir.path() / "results.csv");
  EXPECT_NE(csv.find(",0.05,"), std::string::npos) << csv;
}

}  // namespace
}  // namespace penumbra
