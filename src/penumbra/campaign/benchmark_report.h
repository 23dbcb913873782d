#pragma once
// the results of a benchmark (docs/benchmarks.md): the CSV of every row, the summary table
// (mean +- std over trials, the layout of the URLab paper's Table V), PNG plots and a
// Markdown report that embeds them.

#include <string>
#include <vector>

#include "penumbra/campaign/benchmark_job.h"
#include "penumbra/campaign/benchmark_spec.h"

namespace penumbra {

/// a trial counts as tracked in report.md's summary sentences when its status is ok and it
/// tracked at least this fraction of the ground truth's time (tracked_fraction; the gap limit
/// is 3 ground-truth frame periods, docs/evaluation.md). below it the trial's ATE rests on
/// the stretches it kept and is not comparable with a trial that tracked everything.
inline constexpr double kTrackedFractionThreshold = 0.9;

/// the columns of results.csv, in order.
const std::vector<std::string>& BenchmarkCsvColumns();

/// results.csv text: a header line, then one line per row in the given order; a metric that
/// is NaN is an empty field, numbers in shortest round-trip form, `detail` CSV-quoted.
std::string BenchmarkCsv(const std::vector<BenchmarkRow>& rows);

/// mean +- std of one metric over the trials of one (world, condition, method).
struct SummaryCell {
  int n = 0;                     ///< trials that contribute (status ok)
  double mean = NAN, std = NAN;  ///< std: sample (n - 1) standard deviation, 0 for n = 1
};

/// one (world, condition, method) line of the summary.
struct SummaryLine {
  std::string world, condition, method;
  int trials = 0, ok = 0;
  SummaryCell ate_rmse_m, scaled_ate_m, coverage, rpe_trans_rmse_m, rpe_rot_rmse_deg;
  /// beside coverage and scaled ATE: the tracked path coverage and the ATE scaled by it
  SummaryCell tracked_path_coverage, tracked_scaled_ate_m;
  /// over all trials: a failed trial counts as 0 tracked, and as 0 poses
  SummaryCell tracked_fraction, pose_fraction;
  /// trials that are ok and tracked at least kTrackedFractionThreshold of the time
  int tracked = 0;
};

/// the summary lines in spec order (world, condition, method).
std::vector<SummaryLine> Summarize(const BenchmarkSpec& spec,
                                   const std::vector<BenchmarkRow>& rows);

/// the summary as a Markdown table (one per world). the ATE figures of a line with an ok trial
/// below kTrackedFractionThreshold carry a "†": they rest on part of the ground truth.
std::string SummaryMarkdown(const BenchmarkSpec& spec, const std::vector<SummaryLine>& lines);

/// report.md's tracking sentences, derived from the rows: "Every method tracked at least 0.9
/// of the ground truth's time in every trial" only when every row is ok with tracked_fraction
/// >= kTrackedFractionThreshold; otherwise how many rows did, then a table naming each ok row
/// below the threshold (tracked fraction, poses / frames, pose fraction, ATE) and one of the
/// failed rows (status, detail).
std::string TrackingSummaryMarkdown(const std::vector<BenchmarkRow>& rows);

/// writes results.csv, summary.md, summary.csv, plots/*.png and report.md into `out_dir`.
/// `wall_sec` (the benchmark's wall time) goes into the report.
/// @throws Error if a file cannot be written.
void WriteBenchmarkReport(const BenchmarkSpec& spec, const std::string& out_dir,
                          const std::vector<BenchmarkRow>& rows, double wall_sec);

}  // namespace penumbra
