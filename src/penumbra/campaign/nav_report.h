#pragma once
// the results of a navigation benchmark (docs/benchmarks.md "Navigation"): results.csv (one
// row per (world, episode, condition, method, trial)), the summary in the layout of the URLab
// paper's navigation table (success, collisions, time to goal, goal distance, SC; mean +- std
// over trials), PNG plots (success and SC vs adversity per method; top views of the base's
// paths) and report.md.

#include <string>
#include <vector>

#include "penumbra/campaign/benchmark_report.h"
#include "penumbra/campaign/benchmark_spec.h"
#include "penumbra/campaign/nav_job.h"

namespace penumbra {

/// the columns of a nav benchmark's results.csv, in order.
const std::vector<std::string>& NavCsvColumns();

/// results.csv text: a header line, then one line per row in the given order; an undefined
/// metric (time to goal of a failure, metrics of a run_failed row) is an empty field.
std::string NavCsv(const std::vector<NavRow>& rows);

/// one (world, condition, method) line of the nav summary. per trial, each metric is first
/// taken over the world's episodes (success rate = mean S_i; collisions = mean c_i; time to
/// goal = mean over the successful episodes; goal distance = mean final distance; SC = mean
/// S_i / (1 + c_i)); each cell is then mean +- sample std over the trials (SummaryCell).
/// a run_failed row counts as a failure (S = 0) and adds no collisions or distance.
struct NavSummaryLine {
  std::string world, condition, method;
  int rows = 0, ok = 0;  ///< episode rows, and those with status ok
  SummaryCell success, collisions, time_to_goal_sec, goal_distance_m, sc;
  SummaryCell agent_contacts;  ///< mean contacts agents made per episode (not in SC)
};

/// the summary lines in spec order (world, condition, method).
std::vector<NavSummaryLine> SummarizeNav(const BenchmarkSpec& spec,
                                         const std::vector<NavRow>& rows);

/// the summary as Markdown tables (one per world).
std::string NavSummaryMarkdown(const BenchmarkSpec& spec, const std::vector<NavSummaryLine>& lines);

/// writes results.csv, summary.md, summary.csv, plots/*.png and report.md into `out_dir`.
/// @throws Error if a file cannot be written.
void WriteNavReport(const BenchmarkSpec& spec, const std::string& out_dir,
                    const std::vector<NavRow>& rows, double wall_sec);

}  // namespace penumbra
