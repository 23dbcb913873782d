// `penumbra eval ate|rpe` end to end on the real binary: reports (text and JSON, checked
// against hand-computed values), the plot file, exit codes and error messages.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "app/child_process.h"
#include "common/temp_dir.h"

namespace penumbra {
namespace {

using testing::ProcessResult;
using testing::ReadAll;
using testing::RunPenumbra;

// the trajectories of the ATE hand computation in tests/eval/trajectory_metrics_test.cc:
// without alignment, errors {0, 0.5, 0, 1} m -> rmse 0.5590169943749475, coverage
// 3 / 3.5805863880764948 = 0.837851590451812, scaled ATE 0.6672028802541238 m.
// the estimate is stamped 10 ms late (associated within the default 0.02 s), with commas.
constexpr char kGroundTruth[] =
    "# timestamp tx ty tz qx qy qz qw\n"
    "0 0 0 0 0 0 0 1\n"
    "1 1 0 0 0 0 0 1\n"
    "2 2 0 0 0 0 0 1\n"
    "3 3 0 0 0 0 0 1\n";
constexpr char kEstimate[] =
    "0.01,0,0,0,0,0,0,1\n"
    "1.01,1.3,0.4,0,0,0,0,1\n"
    "2.01,2,0,0,0,0,0,1\n"
    "3.01,3,0.6,0.8,0,0,0,1\n";

class EvalCommandTest : public ::testing::Test {
 protected:
  void SetUp() override {
    gt_ = tmp_.Write("gt.txt", kGroundTruth);
    est_ = tmp_.Write("est.txt", kEstimate);
  }
  ProcessResult Run(const std::vector<std::string>& args) { return RunPenumbra(args, tmp_.path()); }
  testing::TempDir tmp_;
  std::string gt_, est_;
};

TEST_F(EvalCommandTest, AteTextReport) {
  const ProcessResult r = Run({"eval", "ate", gt_, est_, "--align", "none"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_NE(r.out.find("associated    4 pairs (|dt| < 0.02 s, offset 0 s); unmatched: 0 ground "
                       "truth, 0 estimate"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("ATE (m)       rmse 0.559017  mean 0.375  median 0.25  std 0.414578  "
                       "min 0  max 1"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("coverage      0.837852 (ground-truth path 3 m / aligned estimate path "
                       "3.58059 m)"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("scaled ATE    0.667203 m"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("time tracked  1 (3 s of 3 s"), std::string::npos) << r.out;
}

TEST_F(EvalCommandTest, AteJsonOnStdoutAndInAFile) {
  const std::string json_path = (tmp_.path() / "ate.json").string();
  const ProcessResult r =
      Run({"eval", "ate", gt_, est_, "--align", "none", "--format", "json", "--json", json_path});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(nlohmann::json::parse(ReadAll(json_path)), j);
  EXPECT_EQ(j["metric"], "ate");
  EXPECT_EQ(j["ground_truth"]["poses"], 4);
  EXPECT_EQ(j["association"]["pairs"], 4);
  EXPECT_EQ(j["alignment"]["model"], "none");
  EXPECT_DOUBLE_EQ(j["ate_m"]["rmse"].get<double>(), 0.5590169943749475);
  EXPECT_DOUBLE_EQ(j["ate_m"]["median"].get<double>(), 0.25);
  EXPECT_DOUBLE_EQ(j["ate_m"]["std"].get<double>(), 0.414578098794425);
  EXPECT_DOUBLE_EQ(j["coverage"].get<double>(), 0.837851590451812);
  EXPECT_DOUBLE_EQ(j["scaled_ate_m"].get<double>(), 0.6672028802541238);
  EXPECT_DOUBLE_EQ(j["time_tracked"]["fraction"].get<double>(), 1.0);
  // every interval tracked: the whole 3 m ground-truth path, so the ATE is not rescaled
  EXPECT_DOUBLE_EQ(j["tracked_path"]["coverage"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(j["tracked_path"]["scaled_ate_m"].get<double>(), 0.5590169943749475);
  EXPECT_DOUBLE_EQ(j["tracked_path"]["ground_truth_path_m"].get<double>(), 3.0);
  EXPECT_FALSE(j.contains("rpe"));
}

TEST_F(EvalCommandTest, ASparseEstimateReportsItsLostTimeAndPoses) {
  // ground truth at 10 Hz over 0 .. 4 s (41 frames); the estimate kept frames 0, 20, 40. the
  // gap limit is 3 x the ground truth's 0.1 s period: nothing tracked, 3 of 41 poses. with
  // --frame-period 2 (an estimator meant to run at 0.5 Hz) the 2 s intervals count
  std::string gt, est;
  for (int k = 0; k <= 40; ++k) {
    const std::string line = fmt::format("{:.1f} {} 0 0 0 0 0 1\n", 0.1 * k, 0.25 * k);
    gt += line;
    if (k % 20 == 0) est += line;
  }
  const std::string gt_file = tmp_.Write("gt41.txt", gt), est_file = tmp_.Write("est3.txt", est);
  const ProcessResult r = Run({"eval", "ate", gt_file, est_file, "--format", "json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_DOUBLE_EQ(j["time_tracked"]["fraction"].get<double>(), 0.0);
  EXPECT_NEAR(j["time_tracked"]["max_gap_sec"].get<double>(), 0.3, 1e-12);
  EXPECT_NEAR(j["time_tracked"]["frame_period_sec"].get<double>(), 0.1, 1e-12);
  EXPECT_EQ(j["time_tracked"]["associated_poses"], 3);
  EXPECT_EQ(j["time_tracked"]["expected_poses"], 41);
  EXPECT_NEAR(j["time_tracked"]["pose_fraction"].get<double>(), 3.0 / 41.0, 1e-12);
  const ProcessResult text = Run({"eval", "ate", gt_file, est_file});
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("time tracked  0 (0 s of 4 s; intervals > 0.3 s"), std::string::npos)
      << text.out;
  EXPECT_NE(text.out.find("poses         3 associated of 41 expected at 0.1 s per frame "
                          "(0.0731707)"),
            std::string::npos)
      << text.out;
  // the estimate is 20 times sparser than the ground truth: the warning names --frame-period
  EXPECT_NE(text.err.find("is 20 times the ground truth's sample period (0.1 s)"),
            std::string::npos)
      << text.err;
  EXPECT_NE(text.err.find("--frame-period"), std::string::npos) << text.err;
  const ProcessResult slow = Run({"eval", "ate", gt_file, est_file, "--frame-period", "2"});
  ASSERT_EQ(slow.exit_code, 0) << slow.err;
  EXPECT_EQ(slow.err.find("--frame-period"), std::string::npos) << slow.err;
  EXPECT_NE(slow.out.find("time tracked  1 (4 s of 4 s; intervals > 6 s"), std::string::npos)
      << slow.out;
  EXPECT_NE(slow.out.find("3 associated of 3 expected at 2 s per frame (1)"), std::string::npos)
      << slow.out;
}

TEST_F(EvalCommandTest, RpeJsonWithDeltaInFramesAndSeconds) {
  // the RPE hand computation of trajectory_metrics_test.cc: E_02 = (Rz90, (-1, 2, 0)):
  // sqrt(5) m and 90 deg
  const std::string gt = tmp_.Write("q.txt", "0 0 0 0 0 0 0 1\n1 1 0 0 0 0 0 1\n2 2 0 0 0 0 0 1\n");
  const std::string est =
      tmp_.Write("p.txt",
                 "0 0 0 0 0 0 0 1\n1 1 0 0 0 0 0.7071067811865476 0.7071067811865476\n"
                 "2 1 2 0 0 0 0.7071067811865476 0.7071067811865476\n");
  for (const std::vector<std::string>& delta :
       {std::vector<std::string>{"--delta", "2"}, std::vector<std::string>{"--delta-sec", "2"}}) {
    std::vector<std::string> args = {"eval", "rpe", gt, est, "--format", "json", "--align", "none"};
    args.insert(args.end(), delta.begin(), delta.end());
    const ProcessResult r = Run(args);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["metric"], "rpe");
    EXPECT_EQ(j["rpe"]["delta"], 2.0);
    EXPECT_EQ(j["rpe"]["delta"].is_number_integer(), delta[0] == "--delta");
    EXPECT_EQ(j["rpe"]["delta_unit"], delta[0] == "--delta" ? "frames" : "s");
    EXPECT_EQ(j["rpe"]["translation_m"]["count"], 1);
    EXPECT_NEAR(j["rpe"]["translation_m"]["rmse"].get<double>(), std::sqrt(5.0), 1e-12);
    EXPECT_NEAR(j["rpe"]["rotation_deg"]["max"].get<double>(), 90.0, 1e-9);
    EXPECT_FALSE(j.contains("ate_m"));
  }
  const ProcessResult text = Run({"eval", "rpe", gt, est});
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("RPE           delta 1 frame: 2 pose pairs"), std::string::npos)
      << text.out;
  EXPECT_NE(text.out.find("  rotation (deg)    rmse 63.6396  mean 45  median 45"),
            std::string::npos)
      << text.out;
}

TEST_F(EvalCommandTest, NegativeOffsetAssociatesALaterClock) {
  const std::string late = tmp_.Write("late.txt", "100 0 0 0 0 0 0 1\n101 1 0 0 0 0 0 1\n");
  const ProcessResult r = Run({"eval", "ate", gt_, late, "--offset", "-100", "--format", "json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["association"]["pairs"], 2);
  EXPECT_EQ(j["association"]["offset_sec"], -100.0);
  EXPECT_EQ(j["association"]["unmatched_ground_truth"], 2);
}

TEST_F(EvalCommandTest, PlotIsAPng) {
  for (const char* verb : {"ate", "rpe"}) {
    const std::string png = (tmp_.path() / (std::string(verb) + ".png")).string();
    const ProcessResult r = Run({"eval", verb, gt_, est_, "--plot", png});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find("wrote " + png), std::string::npos) << r.err;
    const std::string bytes = ReadAll(png);
    ASSERT_GT(bytes.size(), 1000u);
    EXPECT_EQ(bytes.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  }
}

TEST_F(EvalCommandTest, BadInputExits2WithTheMessageOnStderr) {
  const std::string bad = tmp_.Write("bad.txt", "# c\n0 0 0 0 0 0 0 1\n1 0 0 0 0 0 1\n");
  const std::string late = tmp_.Write("late.txt", "100 0 0 0 0 0 0 1\n101 1 0 0 0 0 0 1\n");
  const std::string missing = (tmp_.path() / "missing.txt").string();
  struct Case {
    std::vector<std::string> args;
    std::string message;
  };
  const std::vector<Case> cases = {
      {{"eval"}, "A subcommand is required"},
      {{"eval", "ate", gt_}, "estimate is required"},
      {{"eval", "ate", gt_, missing}, missing + ": TUM trajectory file not found: " + missing},
      {{"eval", "ate", gt_, bad}, bad + ":3: 7 fields; expected 8 numbers"},
      {{"eval", "ate", gt_, late}, late + ": 0 poses associated with the ground truth " + gt_},
      {{"eval", "ate", gt_, est_, "--max-dt", "0"}, "--max-dt: '0' is out of range"},
      {{"eval", "ate", gt_, est_, "--max-dt", "nan"}, "--max-dt: 'nan' is not a finite decimal"},
      {{"eval", "ate", gt_, est_, "--offset", "0x10"}, "--offset: '0x10' is not a finite decimal"},
      {{"eval", "ate", gt_, est_, "--offset", "+-1"}, "--offset: '+-1' is not a finite decimal"},
      {{"eval", "ate", gt_, est_, "--align", "affine"}, "--align: affine not in {se3,sim3,none}"},
      {{"eval", "ate", gt_, est_, "--format", "xml"}, "--format"},
      {{"eval", "rpe", gt_, est_, "--delta", "0"},
       "--delta: '0' is not an integer in [1, 999999999]"},
      {{"eval", "rpe", gt_, est_, "--delta", "2", "--delta-sec", "1"}, "excludes --delta-sec"},
      {{"eval", "rpe", gt_, est_, "--delta", "9"},
       "--delta: no pair of associated poses is 9 frames apart (4 associated poses"},
      {{"eval", "ate", gt_, est_, "--delta", "2"}, "--delta"},
  };
  for (const Case& c : cases) {
    const ProcessResult r = Run(c.args);
    std::string label;
    for (const std::string& a : c.args) label += a + " ";
    EXPECT_EQ(r.exit_code, 2) << label << "\n" << r.err;
    EXPECT_EQ(r.out, "") << label;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << label << "\nstderr: " << r.err;
  }
}

TEST_F(EvalCommandTest, UnwritableOutputExits1) {
  const std::string json = (tmp_.path() / "no_such_folder" / "ate.json").string();
  const ProcessResult r = Run({"eval", "ate", gt_, est_, "--json", json});
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find(json), std::string::npos) << r.err;
  EXPECT_EQ(r.out, "");
}

}  // namespace
}  // namespace penumbra
