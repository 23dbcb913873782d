#include "penumbra/campaign/benchmark_report.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "penumbra/campaign/benchmark_text.h"
#include "penumbra/campaign/metric_plot.h"
#include "penumbra/core/error.h"
#include "penumbra/eval/trajectory.h"
#include "penumbra/eval/trajectory_evaluation.h"
#include "penumbra/eval/trajectory_plot.h"
#include "penumbra/world/yaml_reader.h"

namespace penumbra {
namespace fs = std::filesystem;
namespace {

using namespace benchmark_text;  // NOLINT: module-internal helpers

// `v` with `digits` decimals, "-" for NaN
std::string FixedOrDash(double v, int digits) {
  return std::isfinite(v) ? fmt::format("{:.{}f}", v, digits) : "-";
}

// a line plot: x = the conditions in spec order, one line per method with error bars (std),
// the y axis up to a round number above the largest mean + std, ticks at 1, 2 or 5 x 10^k
void PlotMetric(const BenchmarkSpec& spec, const std::vector<SummaryLine>& lines,
                const std::string& world, const std::string& label,
                SummaryCell SummaryLine::*metric, const fs::path& file) {
  double ymax = 0;
  for (const SummaryLine& l : lines)
    if (l.world == world && (l.*metric).n > 0)
      ymax = std::max(ymax, (l.*metric).mean + (l.*metric).std);
  if (!(ymax > 0)) ymax = 1;
  const double step = std::pow(10.0, std::floor(std::log10(ymax / 4)));
  double tick = step;
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (ymax / (m * step) <= 6) {
      tick = m * step;
      break;
    }
  MetricPlotStyle style;
  style.ymax = std::ceil(ymax / tick) * tick;
  for (double v = 0; v <= style.ymax + tick / 2; v += tick) style.ticks.push_back(v);
  style.mark_empty = true;  // no trial tracked
  style.footer = "mean +- std over trials; x: no trial tracked";
  PlotMetricVsCondition(spec, world, label, SeriesByMethod(spec, lines, world, metric), style,
                        file);
}

}  // namespace

const std::vector<std::string>& BenchmarkCsvColumns() {
  static const std::vector<std::string> kColumns = {"world",
                                                    "condition",
                                                    "method",
                                                    "trial",
                                                    "seed",
                                                    "status",
                                                    "frames",
                                                    "poses",
                                                    "ate_rmse_m",
                                                    "ate_mean_m",
                                                    "ate_max_m",
                                                    "rpe_trans_rmse_m",
                                                    "rpe_rot_rmse_deg",
                                                    "coverage",
                                                    "scaled_ate_m",
                                                    "tracked_fraction",
                                                    "tracked_path_coverage",
                                                    "tracked_scaled_ate_m",
                                                    "pose_fraction",
                                                    "scale",
                                                    "replay_sec",
                                                    "export_sec",
                                                    "method_sec",
                                                    "eval_sec",
                                                    "detail"};
  return kColumns;
}

std::string BenchmarkCsv(const std::vector<BenchmarkRow>& rows) {
  std::string out;
  for (const std::string& c : BenchmarkCsvColumns()) out += (out.empty() ? "" : ",") + c;
  out += "\n";
  for (const BenchmarkRow& r : rows) {
    out += fmt::format("{},{},{},{},{},{},{},{},", r.world, r.condition, r.method, r.trial, r.seed,
                       r.status, r.frames, r.poses);
    for (double v : {r.ate_rmse_m, r.ate_mean_m, r.ate_max_m, r.rpe_trans_rmse_m,
                     r.rpe_rot_rmse_deg, r.coverage, r.scaled_ate_m, r.tracked_fraction,
                     r.tracked_path_coverage, r.tracked_scaled_ate_m, r.pose_fraction, r.scale})
      out += Field(v) + ",";
    out += fmt::format("{:.3f},{:.3f},{:.3f},{:.3f},", r.replay_sec, r.export_sec, r.method_sec,
                       r.eval_sec);
    out += CsvQuote(r.detail) + "\n";
  }
  return out;
}

std::vector<SummaryLine> Summarize(const BenchmarkSpec& spec,
                                   const std::vector<BenchmarkRow>& rows) {
  std::vector<SummaryLine> lines;
  for (const BenchmarkWorld& w : spec.worlds)
    for (const BenchmarkCondition& c : spec.conditions)
      for (const BenchmarkMethod& m : spec.methods) {
        SummaryLine l;
        l.world = w.name;
        l.condition = c.name;
        l.method = m.name;
        std::vector<double> ate, sate, cov, rpet, rper, tracked, poses, tcov, tsate;
        for (const BenchmarkRow& r : rows) {
          if (r.world != w.name || r.condition != c.name || r.method != m.name) continue;
          ++l.trials;
          const bool ok = r.status == "ok";
          l.ok += ok ? 1 : 0;
          tracked.push_back(ok && std::isfinite(r.tracked_fraction) ? r.tracked_fraction : 0.0);
          poses.push_back(ok && std::isfinite(r.pose_fraction) ? r.pose_fraction : 0.0);
          if (!ok) continue;
          if (r.tracked_fraction >= kTrackedFractionThreshold) ++l.tracked;
          if (std::isfinite(r.ate_rmse_m)) ate.push_back(r.ate_rmse_m);
          if (std::isfinite(r.scaled_ate_m)) sate.push_back(r.scaled_ate_m);
          if (std::isfinite(r.coverage)) cov.push_back(r.coverage);
          if (std::isfinite(r.tracked_path_coverage)) tcov.push_back(r.tracked_path_coverage);
          if (std::isfinite(r.tracked_scaled_ate_m)) tsate.push_back(r.tracked_scaled_ate_m);
          if (std::isfinite(r.rpe_trans_rmse_m)) rpet.push_back(r.rpe_trans_rmse_m);
          if (std::isfinite(r.rpe_rot_rmse_deg)) rper.push_back(r.rpe_rot_rmse_deg);
        }
        l.ate_rmse_m = Cell(ate);
        l.scaled_ate_m = Cell(sate);
        l.coverage = Cell(cov);
        l.tracked_path_coverage = Cell(tcov);
        l.tracked_scaled_ate_m = Cell(tsate);
        l.rpe_trans_rmse_m = Cell(rpet);
        l.rpe_rot_rmse_deg = Cell(rper);
        l.tracked_fraction = Cell(tracked);
        l.pose_fraction = Cell(poses);
        lines.push_back(l);
      }
  return lines;
}

std::string SummaryMarkdown(const BenchmarkSpec& spec, const std::vector<SummaryLine>& lines) {
  std::string out;
  for (const BenchmarkWorld& w : spec.worlds) {
    out += fmt::format(
        "**{}** (mean ± std over the trials that tracked; `ok` = trials with a trajectory "
        "that matches the ground truth; `tracked` = ok trials that tracked at least {} of the "
        "ground truth's time; tracked fraction and pose fraction (associated poses / frames) "
        "count failed trials as 0; † = the ATE figures include trials below that, resting on "
        "part of the ground truth; RPE over {} s)\n\n",
        w.name, FormatNumber(kTrackedFractionThreshold), FormatNumber(spec.metrics.rpe_delta_sec));
    out +=
        "| condition | method | ok | tracked | ATE RMSE (m) | scaled ATE (m) | coverage | tracked "
        "path coverage | tracked-path scaled ATE (m) | tracked fraction | pose fraction | RPE (m) "
        "| RPE (deg) |\n";
    out += "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const SummaryLine& l : lines) {
      if (l.world != w.name) continue;
      const std::string mark = l.tracked < l.ok ? " †" : "";
      out += fmt::format(
          "| {} | {} | {}/{} | {}/{} | {}{} | {}{} | {} | {} | {}{} | {} | {} | {} | {} |\n",
          l.condition, l.method, l.ok, l.trials, l.tracked, l.trials, Pm(l.ate_rmse_m, 4), mark,
          Pm(l.scaled_ate_m, 4), mark, Pm(l.coverage, 3), Pm(l.tracked_path_coverage, 3),
          Pm(l.tracked_scaled_ate_m, 4), mark, Pm(l.tracked_fraction, 3), Pm(l.pose_fraction, 3),
          Pm(l.rpe_trans_rmse_m, 4), Pm(l.rpe_rot_rmse_deg, 2));
    }
    out += "\n";
  }
  return out;
}

std::string TrackingSummaryMarkdown(const std::vector<BenchmarkRow>& rows) {
  const std::string threshold = FormatNumber(kTrackedFractionThreshold);
  std::vector<const BenchmarkRow*> short_rows, failed_rows;
  for (const BenchmarkRow& r : rows) {
    if (r.status != "ok")
      failed_rows.push_back(&r);
    else if (!(r.tracked_fraction >= kTrackedFractionThreshold))
      short_rows.push_back(&r);
  }
  if (short_rows.empty() && failed_rows.empty())
    return fmt::format(
        "Every method tracked at least {} of the ground truth's time in every trial ({} "
        "row{}).\n",
        threshold, rows.size(), rows.size() == 1 ? "" : "s");
  const size_t tracked = rows.size() - short_rows.size() - failed_rows.size();
  std::string md = fmt::format(
      "{} of {} rows tracked at least {} of the ground truth's time; {} ran but tracked less "
      "and {} failed.\n\n",
      tracked, rows.size(), threshold, short_rows.size(), failed_rows.size());
  if (!short_rows.empty()) {
    md += "Tracked less than " + threshold +
          " of the time (their ATE rests on the poses they kept, not comparable with a full "
          "trajectory's):\n\n| world | condition | method | trial | tracked fraction | poses / "
          "frames "
          "| pose fraction | ATE RMSE (m) | scaled ATE (m) "
          "|\n|---|---|---|---|---|---|---|---|---|\n";
    for (const BenchmarkRow* r : short_rows)
      md += fmt::format("| {} | {} | {} | {} | {} | {} / {} | {} | {} | {} |\n", r->world,
                        r->condition, r->method, r->trial, FixedOrDash(r->tracked_fraction, 3),
                        r->poses, r->frames, FixedOrDash(r->pose_fraction, 3),
                        FixedOrDash(r->ate_rmse_m, 4), FixedOrDash(r->scaled_ate_m, 4));
    md += "\n";
  }
  if (!failed_rows.empty()) {
    md +=
        "Failed:\n\n| world | condition | method | trial | status | detail "
        "|\n|---|---|---|---|---|---|\n";
    for (const BenchmarkRow* r : failed_rows)
      md += fmt::format("| {} | {} | {} | {} | {} | {} |\n", r->world, r->condition, r->method,
                        r->trial, r->status, r->detail.substr(0, 200));
  }
  return md;
}

void WriteBenchmarkReport(const BenchmarkSpec& spec, const std::string& out_dir,
                          const std::vector<BenchmarkRow>& rows, double wall_sec) {
  const fs::path out(out_dir);
  WriteText(out / "results.csv", BenchmarkCsv(rows));
  const std::vector<SummaryLine> lines = Summarize(spec, rows);
  const std::string table = SummaryMarkdown(spec, lines);
  WriteText(out / "summary.md", table);
  std::string csv =
      "world,condition,method,trials,ok,ate_rmse_m_mean,ate_rmse_m_std,scaled_ate_m_mean,scaled_"
      "ate_m_std,"
      "coverage_mean,coverage_std,tracked_fraction_mean,tracked_fraction_std,rpe_trans_rmse_m_mean,"
      "rpe_trans_rmse_m_std,tracked_path_coverage_mean,tracked_path_coverage_std,"
      "tracked_scaled_ate_m_mean,tracked_scaled_ate_m_std,tracked,pose_fraction_mean,"
      "pose_fraction_std\n";
  for (const SummaryLine& l : lines)
    csv += fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n",
                       l.world, l.condition, l.method, l.trials, l.ok, Field(l.ate_rmse_m.mean),
                       Field(l.ate_rmse_m.std), Field(l.scaled_ate_m.mean),
                       Field(l.scaled_ate_m.std), Field(l.coverage.mean), Field(l.coverage.std),
                       Field(l.tracked_fraction.mean), Field(l.tracked_fraction.std),
                       Field(l.rpe_trans_rmse_m.mean), Field(l.rpe_trans_rmse_m.std),
                       Field(l.tracked_path_coverage.mean), Field(l.tracked_path_coverage.std),
                       Field(l.tracked_scaled_ate_m.mean), Field(l.tracked_scaled_ate_m.std),
                       l.tracked, Field(l.pose_fraction.mean), Field(l.pose_fraction.std));
  WriteText(out / "summary.csv", csv);

  fs::create_directories(out / "plots");
  std::string md = fmt::format(
      "# Benchmark `{}`\n\nspec: `{}`; {} world(s) x {} condition(s) x {} trial(s) x {} "
      "method(s) = {} rows; wall time {:.1f} s.\n\n## Summary\n\n{}",
      spec.name, spec.file, spec.worlds.size(), spec.conditions.size(), spec.seeds.size(),
      spec.methods.size(), rows.size(), wall_sec, table);
  md += "## Metric vs adversity\n\n";
  for (const BenchmarkWorld& w : spec.worlds) {
    const std::string ate = "plots/" + w.name + "_ate.png",
                      tracked = "plots/" + w.name + "_tracked.png";
    PlotMetric(spec, lines, w.name, "ATE RMSE (m)", &SummaryLine::ate_rmse_m, out / ate);
    PlotMetric(spec, lines, w.name, "tracked fraction", &SummaryLine::tracked_fraction,
               out / tracked);
    md += fmt::format("![{0} ATE]({1})\n\n![{0} tracked fraction]({2})\n\n", w.name, ate, tracked);
  }
  // top views of the first trial of every (world, condition, method) that tracked
  md += "## Trajectories (top view, first trial)\n\n";
  for (const BenchmarkRow& r : rows) {
    if (r.trial != 1 || r.status != "ok") continue;
    const fs::path job = out / "jobs" / (r.world + "__" + r.condition + "__t1");
    const fs::path est_file = job / r.method / "estimate.txt";
    std::error_code ec;
    if (!fs::is_regular_file(est_file, ec)) continue;
    const Trajectory gt = ReadTumTrajectory(job / "groundtruth.txt"),
                     est = ReadTumTrajectory(est_file);
    const BenchmarkMethod* method = nullptr;
    for (const BenchmarkMethod& m : spec.methods)
      if (m.name == r.method) method = &m;
    EvaluationOptions options;
    options.association.max_dt_sec = spec.metrics.max_dt_sec;
    options.alignment = method ? method->align : spec.metrics.align;
    TrajectoryEvaluation e;
    try {
      e = EvaluateTrajectory(gt, est, options, "groundtruth", "estimate");
    } catch (const ConfigError&) {
      continue;
    }
    TrajectoryPlot plot;
    plot.title = fmt::format("{} / {} / {} (trial 1): ATE RMSE {:.4f} m", r.world, r.condition,
                             r.method, e.ate_m.rmse);
    plot.ground_truth_m = gt.Positions();
    plot.ground_truth_time_sec = gt.time_sec;
    plot.estimate_m = e.aligned_estimate_all_positions;
    plot.estimate_time_sec = est.time_sec;
    plot.estimate_label = r.method;
    plot.max_gap_sec = e.tracked.max_gap_sec;
    plot.error_time_sec = e.pair_time_sec;
    plot.error = e.ate_errors_m;
    plot.error_label = "ATE (m)";
    plot.error_rmse = e.ate_m.rmse;
    plot.width = 1000;
    plot.height = 500;
    const std::vector<uint8_t> png = RenderTrajectoryPlotPng(plot);
    const std::string name =
        "plots/traj_" + r.world + "__" + r.condition + "__" + r.method + ".png";
    WriteText(out / name, std::string(png.begin(), png.end()));
    md += fmt::format("![{} {} {}]({})\n\n", r.world, r.condition, r.method, name);
  }
  md +=
      "## Rows\n\nEvery (world, condition, method, trial): [results.csv](results.csv) (columns in "
      "docs/benchmarks.md).\n\n";
  md += TrackingSummaryMarkdown(rows);
  WriteText(out / "report.md", md);
}

}  // namespace penumbra
