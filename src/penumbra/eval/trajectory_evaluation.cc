#include "penumbra/eval/trajectory_evaluation.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "penumbra/core/error.h"

namespace penumbra {

void EvaluationOptions::ValidateOrThrow() const {
  association.ValidateOrThrow();
  rpe_delta.ValidateOrThrow();
  if (frame_period_sec && !(std::isfinite(*frame_period_sec) && *frame_period_sec > 0))
    throw ConfigError(
        "", 0, "frame_period_sec",
        fmt::format("{} is out of range; expected a finite number > 0 (s)", *frame_period_sec));
  if (max_gap_sec && !(std::isfinite(*max_gap_sec) && *max_gap_sec > 0))
    throw ConfigError(
        "", 0, "max_gap_sec",
        fmt::format("{} is out of range; expected a finite number > 0 (s)", *max_gap_sec));
}

const char* AlignmentModelName(AlignmentModel model) {
  switch (model) {
    case AlignmentModel::kNone:
      return "none";
    case AlignmentModel::kSe3:
      return "se3";
    case AlignmentModel::kSim3:
      return "sim3";
  }
  return "?";
}

TrajectoryEvaluation EvaluateTrajectory(const Trajectory& ground_truth, const Trajectory& estimate,
                                        const EvaluationOptions& options,
                                        const std::string& ground_truth_name,
                                        const std::string& estimate_name) {
  options.ValidateOrThrow();
  if (ground_truth.empty() || estimate.empty())
    throw ConfigError(ground_truth.empty() ? ground_truth_name : estimate_name, 0, "",
                      "no poses; expected a trajectory");
  TrajectoryEvaluation r;
  r.ground_truth_poses = ground_truth.size();
  r.estimate_poses = estimate.size();
  r.ground_truth_start_sec = ground_truth.time_sec.front();
  r.ground_truth_end_sec = ground_truth.time_sec.back();
  r.estimate_start_sec = estimate.time_sec.front();
  r.estimate_end_sec = estimate.time_sec.back();
  r.alignment_model = options.alignment;
  r.rpe_delta = options.rpe_delta;

  // 1. association
  r.association =
      AssociateTimestamps(ground_truth.time_sec, estimate.time_sec, options.association);
  const size_t n = r.association.pairs.size();
  if (n < 2)
    throw ConfigError(
        estimate_name, 0, "",
        fmt::format("{} pose{} associated with the ground truth {} (|dt| < {} s after adding "
                    "{} s to the estimate's times; ground truth spans {} .. {} s, estimate "
                    "{} .. {} s); expected at least 2: check --offset and --max-dt",
                    n, n == 1 ? "" : "s", ground_truth_name, options.association.max_dt_sec,
                    options.association.offset_sec, r.ground_truth_start_sec,
                    r.ground_truth_end_sec, r.estimate_start_sec, r.estimate_end_sec));
  r.pair_time_sec.resize(n);
  r.ground_truth_positions.resize(3, static_cast<Eigen::Index>(n));
  Eigen::Matrix3Xd estimate_positions(3, static_cast<Eigen::Index>(n));
  for (size_t k = 0; k < n; ++k) {
    const auto [a, b] = r.association.pairs[k];
    r.pair_time_sec[k] = ground_truth.time_sec[a];
    r.ground_truth_positions.col(static_cast<Eigen::Index>(k)) = ground_truth.X_WB[a].translation();
    estimate_positions.col(static_cast<Eigen::Index>(k)) = estimate.X_WB[b].translation();
  }

  // 2. alignment of the estimate's frame V onto W
  if (options.alignment != AlignmentModel::kNone) {
    const bool with_scale = options.alignment == AlignmentModel::kSim3;
    if (with_scale && (estimate_positions.colwise() - estimate_positions.col(0)).isZero(0))
      throw ConfigError(estimate_name, 0, "",
                        fmt::format("the {} associated estimated positions all coincide; expected "
                                    "a moving estimate for --align sim3 (scale is undefined)",
                                    n));
    r.alignment = AlignUmeyama(estimate_positions, r.ground_truth_positions, with_scale);
  }
  const Similarity3& X_WV = r.alignment;
  r.aligned_estimate_positions.resize(3, static_cast<Eigen::Index>(n));
  for (Eigen::Index k = 0; k < static_cast<Eigen::Index>(n); ++k)
    r.aligned_estimate_positions.col(k) = X_WV.Apply(estimate_positions.col(k));
  r.aligned_estimate_all_positions.resize(3, static_cast<Eigen::Index>(estimate.size()));
  for (size_t k = 0; k < estimate.size(); ++k)
    r.aligned_estimate_all_positions.col(static_cast<Eigen::Index>(k)) =
        X_WV.Apply(estimate.X_WB[k].translation());

  // 3. ATE
  r.ate_errors_m =
      AbsoluteTranslationErrors(r.ground_truth_positions, r.aligned_estimate_positions);
  r.ate_m = SummarizeErrors(r.ate_errors_m);

  // RPE on the aligned estimate: a rigid alignment cancels in P_i^-1 P_j, a scale multiplies
  // the relative translations
  std::vector<Pose> X_W_gt(n), X_W_est(n);
  for (size_t k = 0; k < n; ++k) {
    const auto [a, b] = r.association.pairs[k];
    X_W_gt[k] = ground_truth.X_WB[a];
    Pose X = Pose::Identity();
    X.linear() = X_WV.R_AB * estimate.X_WB[b].linear();
    X.translation() = r.aligned_estimate_positions.col(static_cast<Eigen::Index>(k));
    X_W_est[k] = X;
  }
  r.rpe = RelativePoseErrors(r.pair_time_sec, X_W_gt, X_W_est, options.rpe_delta,
                             options.association.max_dt_sec);
  std::vector<double> rpe_t(r.rpe.size()), rpe_r(r.rpe.size());
  for (size_t k = 0; k < r.rpe.size(); ++k) {
    rpe_t[k] = r.rpe[k].translation_m;
    rpe_r[k] = r.rpe[k].rotation_deg;
  }
  r.rpe_translation_m = SummarizeErrors(rpe_t);
  r.rpe_rotation_deg = SummarizeErrors(rpe_r);

  // benchmark figures
  r.ground_truth_path_m = PathLength(r.ground_truth_positions);
  r.estimate_path_m = PathLength(r.aligned_estimate_positions);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  r.coverage = r.estimate_path_m > 0 ? r.ground_truth_path_m / r.estimate_path_m : nan;
  r.scaled_ate_m = r.coverage > 0 ? r.ate_m.rmse / r.coverage : nan;
  // the gap limit from the ground truth's sampling: the estimate's own median spacing would
  // make a mostly lost estimate's gaps the norm (3 poses of 41 frames read 0.95 tracked)
  r.frame_period_sec = options.frame_period_sec.value_or(MedianPeriod(ground_truth.time_sec));
  const double max_gap_sec = options.max_gap_sec.value_or(kTrackedGapPeriods * r.frame_period_sec);
  r.tracked = ComputeTrackedTime(r.pair_time_sec, r.ground_truth_start_sec, r.ground_truth_end_sec,
                                 max_gap_sec);
  const double span_periods = r.frame_period_sec > 0 ? r.tracked.total_sec / r.frame_period_sec : 0;
  // capped: a tiny frame period over a long span must not overflow the count
  r.expected_poses = static_cast<size_t>(std::min(std::round(span_periods), 1e15)) + 1;
  r.pose_fraction = std::min(1.0, static_cast<double>(n) / static_cast<double>(r.expected_poses));

  // 4. the ground-truth path the tracked intervals cover: the pairs are in ground-truth
  // order, so the ground-truth poses between pair k-1 and pair k are indices a_k-1 .. a_k
  const Eigen::Matrix3Xd gt_all = ground_truth.Positions();
  r.ground_truth_full_path_m = PathLength(gt_all);
  for (size_t k = 1; k < n; ++k) {
    if (!GapIsTracked(r.pair_time_sec[k] - r.pair_time_sec[k - 1], max_gap_sec)) continue;
    const size_t a0 = r.association.pairs[k - 1].first, a1 = r.association.pairs[k].first;
    for (size_t i = a0; i < a1; ++i)
      r.tracked_ground_truth_path_m +=
          (gt_all.col(static_cast<Eigen::Index>(i + 1)) - gt_all.col(static_cast<Eigen::Index>(i)))
              .norm();
  }
  r.tracked_path_coverage = r.ground_truth_full_path_m > 0
                                ? r.tracked_ground_truth_path_m / r.ground_truth_full_path_m
                                : nan;
  r.tracked_scaled_ate_m =
      r.tracked_path_coverage > 0 ? r.ate_m.rmse / r.tracked_path_coverage : nan;
  return r;
}

}  // namespace penumbra
