#include "penumbra/app/eval_command.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <string>

#include "penumbra/core/error.h"
#include "penumbra/core/output_file.h"
#include "penumbra/core/text_match.h"
#include "penumbra/eval/trajectory.h"
#include "penumbra/eval/trajectory_evaluation.h"
#include "penumbra/eval/trajectory_plot.h"

namespace penumbra {
namespace {

using Json = nlohmann::ordered_json;

// a decimal option: any finite number (positive_only = false) or one > 0
CLI::Option* AddNumber(CLI::App* app, const std::string& name, std::optional<double>* target,
                       bool positive_only, const std::string& help) {
  const std::string expected =
      positive_only ? "a finite decimal number > 0" : "a finite decimal number";
  return app
      ->add_option_function<std::string>(
          name, [target](const std::string& s) { *target = *ParseDecimal(s); }, help)
      ->type_name("SEC")
      ->check(CLI::Validator(
          [positive_only, expected](std::string& s) -> std::string {
            const std::optional<double> v = ParseDecimal(s);
            if (!v) return "'" + s + "' is not " + expected;
            if (positive_only && !(*v > 0))
              return "'" + s + "' is out of range; expected " + expected;
            return "";
          },
          expected, ""));
}

// NaN / inf -> null
Json Number(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }

Json StatsJson(const ErrorStats& s) {
  return Json{{"count", s.count},           {"rmse", Number(s.rmse)}, {"mean", Number(s.mean)},
              {"median", Number(s.median)}, {"std", Number(s.std)},   {"min", Number(s.min)},
              {"max", Number(s.max)}};
}

std::string StatsText(const ErrorStats& s) {
  return fmt::format("rmse {:.6g}  mean {:.6g}  median {:.6g}  std {:.6g}  min {:.6g}  max {:.6g}",
                     s.rmse, s.mean, s.median, s.std, s.min, s.max);
}

std::string DeltaText(const RpeDelta& d) {
  if (d.seconds) return fmt::format("{} s", *d.seconds);
  return fmt::format("{} frame{}", d.frames, d.frames == 1 ? "" : "s");
}

double RotationAngleDeg(const Eigen::Matrix3d& R) {
  return Eigen::AngleAxisd(R).angle() * 180.0 / std::numbers::pi;
}

}  // namespace

struct EvalCommand::State {
  CLI::App* eval = nullptr;
  CLI::App* ate = nullptr;
  CLI::App* rpe = nullptr;
  std::string ground_truth_path, estimate_path;
  std::string align = "se3";
  std::string format = "text";
  std::string json_path, plot_path;
  std::optional<double> max_dt_sec, offset_sec, frame_period_sec, max_gap_sec, delta_sec;
  int64_t delta_frames = 1;

  Json ToJson(bool ate_verb, const TrajectoryEvaluation& r) const;
  std::string ToText(bool ate_verb, const TrajectoryEvaluation& r) const;
};

EvalCommand::EvalCommand() : state_(std::make_unique<State>()) {}
EvalCommand::~EvalCommand() = default;

std::string EvalCommand::name() const { return "eval"; }

std::string EvalCommand::summary() const {
  return "trajectory metrics of an estimate against ground truth (TUM files; "
         "docs/evaluation.md)";
}

void EvalCommand::AddOptions(CLI::App* eval) {
  State& s = *state_;
  s.eval = eval;
  s.eval->require_subcommand(1);
  s.ate = s.eval->add_subcommand(
      "ate", "absolute trajectory error, coverage, scaled ATE and time tracked");
  s.rpe = s.eval->add_subcommand("rpe", "relative pose error (translation and rotation)");
  for (CLI::App* verb : {s.ate, s.rpe}) {
    verb->add_option("ground_truth", s.ground_truth_path,
                     "ground truth, TUM format: timestamp tx ty tz qx qy qz qw")
        ->required();
    verb->add_option("estimate", s.estimate_path, "estimated trajectory, TUM format")->required();
    verb->add_option("--align", s.align,
                     "alignment of the estimate onto the ground truth (Umeyama): se3 (rotation + "
                     "translation), sim3 (+ scale) or none; default se3")
        ->check(CLI::IsMember({"se3", "sim3", "none"}));
    AddNumber(verb, "--max-dt", &s.max_dt_sec, true,
              "largest |dt| of an associated pose pair, s (default 0.02)");
    AddNumber(verb, "--offset", &s.offset_sec, false,
              "added to the estimate's timestamps before association, s (default 0)");
    AddNumber(verb, "--frame-period", &s.frame_period_sec, true,
              "the sample period the estimate should have (its camera's frame period), s "
              "(default the ground truth's median sample period)");
    AddNumber(verb, "--max-gap", &s.max_gap_sec, true,
              "longest interval between associated poses that counts as tracked, s (default 3 x "
              "the frame period)");
    verb->add_option("--json", s.json_path, "also write the report as JSON to this file");
    verb->add_option("--plot", s.plot_path,
                     "write a PNG: top view of both trajectories and the error over time");
    verb->add_option("--format", s.format, "stdout report: text (default) or json")
        ->check(CLI::IsMember({"text", "json"}));
  }
  CLI::Option* delta = s.rpe->add_option_function<std::string>(
      "--delta", [&s](const std::string& v) { s.delta_frames = std::stoll(v); },
      "pose pairs this many associated poses apart (default 1)");
  delta->type_name("N")->check(CLI::Validator(
      [](std::string& v) -> std::string {
        const bool digits =
            !v.empty() && v.size() <= 9 && v.find_first_not_of("0123456789") == std::string::npos;
        if (!digits || std::stoll(v) < 1) return "'" + v + "' is not an integer in [1, 999999999]";
        return "";
      },
      "an integer in [1, 999999999]", ""));
  CLI::Option* delta_sec = AddNumber(s.rpe, "--delta-sec", &s.delta_sec, true,
                                     "pose pairs this many seconds apart (instead of --delta)");
  delta->excludes(delta_sec);
}

Json EvalCommand::State::ToJson(bool ate_verb, const TrajectoryEvaluation& r) const {
  Json j;
  j["metric"] = ate_verb ? "ate" : "rpe";
  j["ground_truth"] = {{"file", ground_truth_path},
                       {"poses", r.ground_truth_poses},
                       {"start_sec", r.ground_truth_start_sec},
                       {"end_sec", r.ground_truth_end_sec}};
  j["estimate"] = {{"file", estimate_path},
                   {"poses", r.estimate_poses},
                   {"start_sec", r.estimate_start_sec},
                   {"end_sec", r.estimate_end_sec}};
  const AssociationOptions a = EvaluationOptions{}.association;
  j["association"] = {{"max_dt_sec", max_dt_sec.value_or(a.max_dt_sec)},
                      {"offset_sec", offset_sec.value_or(a.offset_sec)},
                      {"pairs", r.association.pairs.size()},
                      {"unmatched_ground_truth", r.association.unmatched_ground_truth},
                      {"unmatched_estimate", r.association.unmatched_estimate}};
  Json rotation = Json::array();
  for (int row = 0; row < 3; ++row)
    rotation.push_back(
        {r.alignment.R_AB(row, 0), r.alignment.R_AB(row, 1), r.alignment.R_AB(row, 2)});
  j["alignment"] = {
      {"model", AlignmentModelName(r.alignment_model)},
      {"scale", r.alignment.scale},
      {"rotation", rotation},
      {"translation_m", {r.alignment.p_AB.x(), r.alignment.p_AB.y(), r.alignment.p_AB.z()}}};
  if (ate_verb) {
    j["ate_m"] = StatsJson(r.ate_m);
    j["ground_truth_path_m"] = r.ground_truth_path_m;
    j["estimate_path_m"] = r.estimate_path_m;
    j["coverage"] = Number(r.coverage);
    j["scaled_ate_m"] = Number(r.scaled_ate_m);
    j["time_tracked"] = {
        {"fraction", Number(r.tracked.fraction)}, {"tracked_sec", r.tracked.tracked_sec},
        {"total_sec", r.tracked.total_sec},       {"max_gap_sec", r.tracked.max_gap_sec},
        {"frame_period_sec", r.frame_period_sec}, {"associated_poses", r.association.pairs.size()},
        {"expected_poses", r.expected_poses},     {"pose_fraction", Number(r.pose_fraction)}};
    // beside the paper's coverage: the ground-truth path the tracked intervals cover
    j["tracked_path"] = {{"coverage", Number(r.tracked_path_coverage)},
                         {"scaled_ate_m", Number(r.tracked_scaled_ate_m)},
                         {"tracked_ground_truth_path_m", r.tracked_ground_truth_path_m},
                         {"ground_truth_path_m", r.ground_truth_full_path_m}};
  } else {
    j["rpe"] = {
        {"delta", r.rpe_delta.seconds ? Json(*r.rpe_delta.seconds) : Json(r.rpe_delta.frames)},
        {"delta_unit", r.rpe_delta.seconds ? "s" : "frames"},
        {"translation_m", StatsJson(r.rpe_translation_m)},
        {"rotation_deg", StatsJson(r.rpe_rotation_deg)}};
  }
  return j;
}

std::string EvalCommand::State::ToText(bool ate_verb, const TrajectoryEvaluation& r) const {
  const AssociationOptions a = EvaluationOptions{}.association;
  std::string t;
  t += fmt::format("ground truth  {}: {} poses, {:.6g} .. {:.6g} s\n", ground_truth_path,
                   r.ground_truth_poses, r.ground_truth_start_sec, r.ground_truth_end_sec);
  t += fmt::format("estimate      {}: {} poses, {:.6g} .. {:.6g} s\n", estimate_path,
                   r.estimate_poses, r.estimate_start_sec, r.estimate_end_sec);
  t += fmt::format(
      "associated    {} pairs (|dt| < {} s, offset {} s); unmatched: {} ground "
      "truth, {} estimate\n",
      r.association.pairs.size(), max_dt_sec.value_or(a.max_dt_sec),
      offset_sec.value_or(a.offset_sec), r.association.unmatched_ground_truth,
      r.association.unmatched_estimate);
  const Eigen::Vector3d& p = r.alignment.p_AB;
  t += fmt::format(
      "alignment     {}: scale {:.6g}, rotation {:.6g} deg, translation ({:.6g}, "
      "{:.6g}, {:.6g}) m\n",
      AlignmentModelName(r.alignment_model), r.alignment.scale, RotationAngleDeg(r.alignment.R_AB),
      p.x(), p.y(), p.z());
  if (ate_verb) {
    t += fmt::format("ATE (m)       {}\n", StatsText(r.ate_m));
    if (std::isfinite(r.coverage))
      t += fmt::format(
          "coverage      {:.6g} (ground-truth path {:.6g} m / aligned estimate path "
          "{:.6g} m)\n",
          r.coverage, r.ground_truth_path_m, r.estimate_path_m);
    else
      t += "coverage      undefined (the aligned estimate does not move)\n";
    t += fmt::format("scaled ATE    {:.6g} m\n", r.scaled_ate_m);
    t += fmt::format(
        "time tracked  {:.6g} ({:.6g} s of {:.6g} s; intervals > {:.6g} s between "
        "associated poses not counted)\n",
        r.tracked.fraction, r.tracked.tracked_sec, r.tracked.total_sec, r.tracked.max_gap_sec);
    t += fmt::format(
        "poses         {} associated of {} expected at {:.6g} s per frame ({:.6g}); the ATE rests "
        "on these\n",
        r.association.pairs.size(), r.expected_poses, r.frame_period_sec, r.pose_fraction);
    if (std::isfinite(r.tracked_path_coverage))
      t += fmt::format(
          "tracked path  coverage {:.6g} (ground-truth path over tracked intervals {:.6g} m / "
          "whole ground-truth path {:.6g} m), scaled ATE {:.6g} m\n",
          r.tracked_path_coverage, r.tracked_ground_truth_path_m, r.ground_truth_full_path_m,
          r.tracked_scaled_ate_m);
    else
      t += "tracked path  undefined (the ground truth does not move)\n";
  } else {
    t += fmt::format("RPE           delta {}: {} pose pairs\n", DeltaText(r.rpe_delta),
                     r.rpe.size());
    t += fmt::format("  translation (m)   {}\n", StatsText(r.rpe_translation_m));
    t += fmt::format("  rotation (deg)    {}\n", StatsText(r.rpe_rotation_deg));
  }
  return t;
}

int EvalCommand::Run(const CommandArgs&) {
  const State& s = *state_;
  const bool ate_verb = s.ate->parsed();
  EvaluationOptions options;
  if (s.max_dt_sec) options.association.max_dt_sec = *s.max_dt_sec;
  if (s.offset_sec) options.association.offset_sec = *s.offset_sec;
  options.alignment = s.align == "sim3"   ? AlignmentModel::kSim3
                      : s.align == "none" ? AlignmentModel::kNone
                                          : AlignmentModel::kSe3;
  options.rpe_delta.frames = s.delta_frames;
  options.rpe_delta.seconds = s.delta_sec;
  options.frame_period_sec = s.frame_period_sec;
  options.max_gap_sec = s.max_gap_sec;

  const Trajectory ground_truth = ReadTumTrajectory(s.ground_truth_path);
  const Trajectory estimate = ReadTumTrajectory(s.estimate_path);
  const TrajectoryEvaluation r =
      EvaluateTrajectory(ground_truth, estimate, options, s.ground_truth_path, s.estimate_path);
  if (!ate_verb && r.rpe.empty())
    throw ConfigError("", 0, r.rpe_delta.seconds ? "--delta-sec" : "--delta",
                      fmt::format("no pair of associated poses is {} apart ({} associated poses, "
                                  "{:.6g} .. {:.6g} s); expected a shorter delta",
                                  DeltaText(r.rpe_delta), r.association.pairs.size(),
                                  r.pair_time_sec.front(), r.pair_time_sec.back()));

  // a ground truth sampled faster than the camera (motion capture at 100 Hz, images at 30 Hz)
  // makes every frame interval a gap under the default limit: say so, and what to give
  const double estimate_period_sec = MedianPeriod(estimate.time_sec);
  if (!s.frame_period_sec && !s.max_gap_sec && estimate_period_sec > 2 * r.frame_period_sec)
    spdlog::warn(
        "the estimate's median pose spacing ({:.6g} s) is {:.3g} times the ground truth's sample "
        "period ({:.6g} s), which the tracked time's gap limit comes from: an estimate that lost "
        "frames reads as such; if the camera ran slower than the ground truth was sampled (e.g. "
        "motion capture), give its frame period with --frame-period",
        estimate_period_sec, estimate_period_sec / r.frame_period_sec, r.frame_period_sec);

  const Json json = s.ToJson(ate_verb, r);
  if (!s.json_path.empty()) {
    WriteFileAtomic(s.json_path, json.dump(2) + "\n");
    spdlog::info("wrote {}", s.json_path);
  }
  if (!s.plot_path.empty()) {
    TrajectoryPlot plot;
    plot.title = fmt::format("{}: {} vs ground truth {} ({} alignment)", ate_verb ? "ATE" : "RPE",
                             std::filesystem::path(s.estimate_path).filename().string(),
                             std::filesystem::path(s.ground_truth_path).filename().string(),
                             AlignmentModelName(r.alignment_model));
    plot.ground_truth_m = ground_truth.Positions();
    plot.ground_truth_time_sec = ground_truth.time_sec;
    plot.estimate_m = r.aligned_estimate_all_positions;
    plot.estimate_time_sec = estimate.time_sec;
    plot.estimate_label = fmt::format("estimate ({})", AlignmentModelName(r.alignment_model));
    plot.max_gap_sec = r.tracked.max_gap_sec;
    if (ate_verb) {
      plot.error_time_sec = r.pair_time_sec;
      plot.error = r.ate_errors_m;
      plot.error_label = "ATE (m)";
      plot.error_rmse = r.ate_m.rmse;
    } else {
      for (const RelativePoseError& e : r.rpe) {
        plot.error_time_sec.push_back(r.pair_time_sec[e.i]);
        plot.error.push_back(e.translation_m);
      }
      plot.error_label = fmt::format("RPE translation (m), delta {}", DeltaText(r.rpe_delta));
      plot.error_rmse = r.rpe_translation_m.rmse;
    }
    const std::vector<uint8_t> png = RenderTrajectoryPlotPng(plot);
    WriteFileAtomic(s.plot_path,
                    std::string_view(reinterpret_cast<const char*>(png.data()), png.size()));
    spdlog::info("wrote {}", s.plot_path);
  }
  if (s.format == "json")
    std::cout << json.dump(2) << "\n";
  else
    std::cout << s.ToText(ate_verb, r);
  std::cout.flush();
  return 0;
}

}  // namespace penumbra
