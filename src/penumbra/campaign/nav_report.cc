#include "penumbra/campaign/nav_report.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "penumbra/campaign/benchmark_text.h"
#include "penumbra/campaign/metric_plot.h"
#include "penumbra/campaign/nav_metrics.h"
#include "penumbra/core/error.h"
#include "penumbra/world/yaml_reader.h"

namespace penumbra {
namespace fs = std::filesystem;
namespace {

using namespace benchmark_text;  // NOLINT: module-internal helpers

// metric vs condition, one line per method (mean, std error bars), y from 0 to ymax in fifths
void PlotMetric(const BenchmarkSpec& spec, const std::vector<NavSummaryLine>& lines,
                const std::string& world, const std::string& label,
                SummaryCell NavSummaryLine::*metric, double ymax, const fs::path& file) {
  MetricPlotStyle style;
  style.ymax = ymax;
  for (int k = 0; k <= 5; ++k) style.ticks.push_back(ymax * k / 5);
  style.clamp = true;
  style.footer = "mean +- std over trials";
  PlotMetricVsCondition(spec, world, label, SeriesByMethod(spec, lines, world, metric), style,
                        file);
}

// top view of every trial's base path of one (world, episode, condition, method): the start
// (square), the goal and its success radius (circle), one colour per trial
void PlotPaths(const std::string& title, const std::vector<const NavRow*>& rows,
               const fs::path& file) {
  const int S = 640, margin = 50;
  cv::Mat img(S + 40, S, CV_8UC3, cv::Scalar(255, 255, 255));
  double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
  const auto grow = [&](double x, double y, double r) {
    x0 = std::min(x0, x - r), x1 = std::max(x1, x + r);
    y0 = std::min(y0, y - r), y1 = std::max(y1, y + r);
  };
  for (const NavRow* r : rows) {
    grow(r->goal_x, r->goal_y, r->radius_m);
    for (const auto& [x, y] : r->path_xy) grow(x, y, 0.2);
  }
  const double span = std::max({x1 - x0, y1 - y0, 1.0});
  const double cx = (x0 + x1) / 2, cy = (y0 + y1) / 2, scale = (S - 2 * margin) / span;
  // world x to the right, world y up
  const auto P = [&](double x, double y) {
    return cv::Point(static_cast<int>(std::lround(S / 2 + (x - cx) * scale)),
                     static_cast<int>(std::lround(40 + S / 2 - (y - cy) * scale)));
  };
  const cv::Scalar black(0, 0, 0), grey(200, 200, 200);
  // a 1 m grid
  for (double gx = std::floor(cx - span); gx <= cx + span; gx += 1)
    cv::line(img, P(gx, cy - span), P(gx, cy + span), grey, 1);
  for (double gy = std::floor(cy - span); gy <= cy + span; gy += 1)
    cv::line(img, P(cx - span, gy), P(cx + span, gy), grey, 1);
  cv::rectangle(img, {0, 0}, {S, 40}, cv::Scalar(255, 255, 255), cv::FILLED);
  cv::putText(img, title, {10, 26}, cv::FONT_HERSHEY_SIMPLEX, 0.5, black, 1, cv::LINE_AA);
  if (!rows.empty()) {
    const NavRow& r0 = *rows.front();
    cv::circle(img, P(r0.goal_x, r0.goal_y), static_cast<int>(std::lround(r0.radius_m * scale)),
               cv::Scalar(0, 160, 0), 2, cv::LINE_AA);
    cv::drawMarker(img, P(r0.goal_x, r0.goal_y), cv::Scalar(0, 160, 0), cv::MARKER_CROSS, 14, 2);
  }
  for (size_t i = 0; i < rows.size(); ++i) {
    const cv::Scalar col = PlotColour(i);
    std::vector<cv::Point> pts;
    for (const auto& [x, y] : rows[i]->path_xy) pts.push_back(P(x, y));
    if (pts.empty()) continue;
    cv::polylines(img, pts, false, col, 2, cv::LINE_AA);
    cv::drawMarker(img, pts.front(), col, cv::MARKER_SQUARE, 10, 2);
    cv::putText(
        img,
        fmt::format(
            "trial {}: {}{}", rows[i]->trial, rows[i]->success ? "success" : "failure",
            (rows[i]->collisions ? fmt::format(", {} coll.", rows[i]->collisions) : std::string()) +
                (rows[i]->agent_contacts ? fmt::format(", {} by agents", rows[i]->agent_contacts)
                                         : std::string())),
        {10, S + 30 - 18 * static_cast<int>(rows.size() - 1 - i)}, cv::FONT_HERSHEY_SIMPLEX, 0.45,
        col, 1, cv::LINE_AA);
  }
  cv::putText(img, "1 m grid; x right, y up", {S - 190, S + 30}, cv::FONT_HERSHEY_SIMPLEX, 0.4,
              cv::Scalar(90, 90, 90), 1, cv::LINE_AA);
  if (!cv::imwrite(file.string(), img)) throw Error("cannot write " + file.string());
}

}  // namespace

const std::vector<std::string>& NavCsvColumns() {
  static const std::vector<std::string> kColumns = {"world",
                                                    "episode",
                                                    "condition",
                                                    "method",
                                                    "trial",
                                                    "seed",
                                                    "status",
                                                    "end",
                                                    "success",
                                                    "collisions",
                                                    "agent_contacts",
                                                    "sc",
                                                    "time_to_goal_sec",
                                                    "final_goal_distance_m",
                                                    "episode_time_sec",
                                                    "path_length_m",
                                                    "fell",
                                                    "goal_x",
                                                    "goal_y",
                                                    "radius_m",
                                                    "timeout_sec",
                                                    "method_sec",
                                                    "run_sec",
                                                    "eval_sec",
                                                    "detail"};
  return kColumns;
}

std::string NavCsv(const std::vector<NavRow>& rows) {
  std::string out;
  for (const std::string& c : NavCsvColumns()) out += (out.empty() ? "" : ",") + c;
  out += "\n";
  for (const NavRow& r : rows) {
    const bool measured = r.status != "run_failed";
    out += fmt::format("{},{},{},{},{},{},{},{},", r.world, r.episode, r.condition, r.method,
                       r.trial, r.seed, r.status, r.end);
    out += measured ? fmt::format("{},{},{},{},", r.success ? 1 : 0, r.collisions, r.agent_contacts,
                                  Field(r.sc))
                    : std::string("0,,,0,");
    out += fmt::format("{},{},{},{},{},", Field(r.time_to_goal_sec), Field(r.final_goal_distance_m),
                       Field(r.episode_time_sec), Field(r.path_length_m),
                       measured ? (r.fell ? "1" : "0") : "");
    out += fmt::format("{},{},{},{},", Field(r.goal_x), Field(r.goal_y), Field(r.radius_m),
                       Field(r.timeout_sec));
    out += fmt::format("{:.3f},{:.3f},{:.3f},", r.method_sec, r.run_sec, r.eval_sec);
    out += CsvQuote(r.detail) + "\n";
  }
  return out;
}

std::vector<NavSummaryLine> SummarizeNav(const BenchmarkSpec& spec,
                                         const std::vector<NavRow>& rows) {
  std::vector<NavSummaryLine> lines;
  for (const BenchmarkWorld& w : spec.worlds)
    for (const BenchmarkCondition& c : spec.conditions)
      for (const BenchmarkMethod& m : spec.methods) {
        NavSummaryLine l;
        l.world = w.name;
        l.condition = c.name;
        l.method = m.name;
        std::vector<double> success, collisions, agent_contacts, ttg, dist, sc;
        for (uint64_t seed : spec.seeds) {
          std::vector<bool> s;
          std::vector<int> coll, agent;
          std::vector<double> t, d;
          for (const NavRow& r : rows) {
            if (r.world != w.name || r.condition != c.name || r.method != m.name || r.seed != seed)
              continue;
            ++l.rows;
            l.ok += r.status == "ok" ? 1 : 0;
            const bool measured = r.status != "run_failed";
            s.push_back(measured && r.success);
            coll.push_back(measured ? r.collisions : 0);
            agent.push_back(measured ? r.agent_contacts : 0);
            if (measured && r.success && std::isfinite(r.time_to_goal_sec))
              t.push_back(r.time_to_goal_sec);
            if (measured && std::isfinite(r.final_goal_distance_m))
              d.push_back(r.final_goal_distance_m);
          }
          if (s.empty()) continue;
          double ns = 0, nc = 0;
          double na = 0;
          for (size_t i = 0; i < s.size(); ++i) ns += s[i] ? 1 : 0, nc += coll[i], na += agent[i];
          success.push_back(ns / s.size());
          collisions.push_back(nc / s.size());
          agent_contacts.push_back(na / s.size());
          sc.push_back(SuccessWeightedByCollisions(s, coll));
          if (!t.empty()) {
            double sum = 0;
            for (double x : t) sum += x;
            ttg.push_back(sum / t.size());
          }
          if (!d.empty()) {
            double sum = 0;
            for (double x : d) sum += x;
            dist.push_back(sum / d.size());
          }
        }
        l.success = Cell(success);
        l.collisions = Cell(collisions);
        l.agent_contacts = Cell(agent_contacts);
        l.time_to_goal_sec = Cell(ttg);
        l.goal_distance_m = Cell(dist);
        l.sc = Cell(sc);
        lines.push_back(l);
      }
  return lines;
}

std::string NavSummaryMarkdown(const BenchmarkSpec& spec,
                               const std::vector<NavSummaryLine>& lines) {
  std::string out;
  for (const BenchmarkWorld& w : spec.worlds) {
    out += fmt::format(
        "**{}** ({} episode(s) per trial; per trial the mean over the episodes, then mean ± std "
        "over trials; time to goal over the successful episodes; collisions the robot caused, "
        "debounced over {} s, feet/wheels on the floor not counted; agent contacts: agents that "
        "walked or drove into the robot, not in SC; SC = mean S/(1+c))\n\n",
        w.name, w.episodes.size(), FormatNumber(spec.nav_metrics.debounce_sec));
    out +=
        "| condition | method | ok | success | collisions | agent contacts | time to goal (s) | "
        "goal distance (m) | SC |\n|---|---|---|---|---|---|---|---|---|\n";
    for (const NavSummaryLine& l : lines) {
      if (l.world != w.name) continue;
      out +=
          fmt::format("| {} | {} | {}/{} | {} | {} | {} | {} | {} | {} |\n", l.condition, l.method,
                      l.ok, l.rows, Pm(l.success, 2), Pm(l.collisions, 2), Pm(l.agent_contacts, 2),
                      Pm(l.time_to_goal_sec, 1), Pm(l.goal_distance_m, 2), Pm(l.sc, 2));
    }
    out += "\n";
  }
  return out;
}

void WriteNavReport(const BenchmarkSpec& spec, const std::string& out_dir,
                    const std::vector<NavRow>& rows, double wall_sec) {
  const fs::path out(out_dir);
  WriteText(out / "results.csv", NavCsv(rows));
  const std::vector<NavSummaryLine> lines = SummarizeNav(spec, rows);
  const std::string table = NavSummaryMarkdown(spec, lines);
  WriteText(out / "summary.md", table);
  std::string csv =
      "world,condition,method,rows,ok,success_mean,success_std,collisions_mean,collisions_std,"
      "agent_contacts_mean,agent_contacts_std,time_to_goal_sec_mean,time_to_goal_sec_std,goal_"
      "distance_m_mean,goal_distance_m_std,"
      "sc_mean,sc_std\n";
  for (const NavSummaryLine& l : lines)
    csv +=
        fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", l.world, l.condition,
                    l.method, l.rows, l.ok, Field(l.success.mean), Field(l.success.std),
                    Field(l.collisions.mean), Field(l.collisions.std), Field(l.agent_contacts.mean),
                    Field(l.agent_contacts.std), Field(l.time_to_goal_sec.mean),
                    Field(l.time_to_goal_sec.std), Field(l.goal_distance_m.mean),
                    Field(l.goal_distance_m.std), Field(l.sc.mean), Field(l.sc.std));
  WriteText(out / "summary.csv", csv);

  fs::create_directories(out / "plots");
  size_t episodes = 0;
  for (const BenchmarkWorld& w : spec.worlds) episodes += w.episodes.size();
  std::string md = fmt::format(
      "# Navigation benchmark `{}`\n\nspec: `{}`; {} episode(s) over {} world(s) x {} "
      "condition(s) x {} method(s) x {} trial(s) = {} rows; wall time {:.1f} s.\n\n## "
      "Summary\n\n{}",
      spec.name, spec.file, episodes, spec.worlds.size(), spec.conditions.size(),
      spec.methods.size(), spec.seeds.size(), rows.size(), wall_sec, table);
  md += "## Metric vs adversity\n\n";
  for (const BenchmarkWorld& w : spec.worlds) {
    const std::string success = "plots/" + w.name + "_success.png",
                      sc = "plots/" + w.name + "_sc.png";
    PlotMetric(spec, lines, w.name, "success rate", &NavSummaryLine::success, 1.0, out / success);
    PlotMetric(spec, lines, w.name, "SC (success weighted by collisions)", &NavSummaryLine::sc, 1.0,
               out / sc);
    md += fmt::format("![{0} success]({1})\n\n![{0} SC]({2})\n\n", w.name, success, sc);
  }
  md += "## Paths (top view, every trial)\n\n";
  for (const BenchmarkWorld& w : spec.worlds)
    for (const NavEpisode& e : w.episodes)
      for (const BenchmarkCondition& c : spec.conditions)
        for (const BenchmarkMethod& m : spec.methods) {
          std::vector<const NavRow*> sel;
          for (const NavRow& r : rows)
            if (r.world == w.name && r.episode == e.name && r.condition == c.name &&
                r.method == m.name && !r.path_xy.empty())
              sel.push_back(&r);
          if (sel.empty()) continue;
          std::sort(sel.begin(), sel.end(),
                    [](const NavRow* a, const NavRow* b) { return a->trial < b->trial; });
          const std::string name =
              "plots/path_" + w.name + "__" + e.name + "__" + c.name + "__" + m.name + ".png";
          PlotPaths(fmt::format("{} / {} / {} / {}: goal ({:g}, {:g}) r {:g} m", w.name, e.name,
                                c.name, m.name, e.goal_x, e.goal_y, e.radius_m),
                    sel, out / name);
          md += fmt::format("![{} {} {} {}]({})\n\n", w.name, e.name, c.name, m.name, name);
        }
  md +=
      "## Rows\n\nEvery (world, episode, condition, method, trial): [results.csv](results.csv) "
      "(columns in docs/benchmarks.md).\n\n";
  int failed = 0;
  for (const NavRow& r : rows)
    if (r.status != "ok") {
      if (failed++ == 0)
        md +=
            "| world | episode | condition | method | trial | status | detail |\n"
            "|---|---|---|---|---|---|---|\n";
      md += fmt::format("| {} | {} | {} | {} | {} | {} | {} |\n", r.world, r.episode, r.condition,
                        r.method, r.trial, r.status, r.detail.substr(0, 200));
    }
  if (failed == 0) md += "Every method process ended normally in every episode.\n";
  WriteText(out / "report.md", md);
}

}  // namespace penumbra
