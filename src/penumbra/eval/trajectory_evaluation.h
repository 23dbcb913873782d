#pragma once
// one evaluation of an estimated trajectory against ground truth, as `penumbra eval ate|rpe`
// runs it (docs/evaluation.md):
//   1. associate timestamps (association.h, TUM's associate.py rule);
//   2. align the associated estimated positions onto the ground truth (umeyama.h: se3, sim3
//      or none); the transform applies to the whole estimate (positions c R p + t,
//      orientations R R_WB);
//   3. ATE, RPE (trajectory_metrics.h) and the benchmark figures of the URLab paper:
//      coverage = ground-truth path length / aligned estimated path length, both over the
//      associated poses in ground-truth time order; scaled ATE = ATE RMSE / coverage;
//      fraction of ground-truth time tracked (ComputeTrackedTime), with the gap limit taken
//      from the ground truth's sampling (or the caller's frame period), never from the
//      estimate's own spacing: a mostly lost estimate's spacing is itself a gap;
//   4. beside the paper's coverage, which rewards an estimate that barely moves (its path is
//      short, so coverage > 1 and the scaled ATE shrinks): the tracked path coverage = the
//      ground-truth path length over the tracked intervals (between consecutive associated
//      poses, GapIsTracked) / the length of the whole ground-truth path, in [0, 1], and the
//      tracked scaled ATE = ATE RMSE / tracked path coverage (>= ATE RMSE; docs/evaluation.md).

#include <optional>
#include <string>
#include <vector>

#include "penumbra/eval/association.h"
#include "penumbra/eval/trajectory.h"
#include "penumbra/eval/trajectory_metrics.h"
#include "penumbra/eval/umeyama.h"

namespace penumbra {

/// what EvaluateTrajectory does; defaults are those of `penumbra eval`.
struct EvaluationOptions {
  AssociationOptions association;
  AlignmentModel alignment = AlignmentModel::kSe3;
  RpeDelta rpe_delta;
  /// the sample period the estimate should have (its camera's frame period), s; unset: the
  /// ground truth's median sample period (MedianPeriod). set it when the ground truth is
  /// sampled faster than the estimator's input (e.g. 100 Hz motion capture, a 30 Hz camera).
  std::optional<double> frame_period_sec;
  /// the longest interval between consecutive associated poses that counts as tracked, s;
  /// unset: kTrackedGapPeriods x the frame period above
  std::optional<double> max_gap_sec;

  /// @throws ConfigError naming the key (max_dt_sec, offset_sec, delta, delta_sec,
  ///         frame_period_sec, max_gap_sec) of a value out of range.
  void ValidateOrThrow() const;
};

/// the results. positions in the ground truth's world frame W, m; times s.
struct TrajectoryEvaluation {
  size_t ground_truth_poses = 0, estimate_poses = 0;
  double ground_truth_start_sec = 0, ground_truth_end_sec = 0;
  double estimate_start_sec = 0, estimate_end_sec = 0;
  Association association;
  /// X_WV: the estimate's frame V into W (identity for AlignmentModel::kNone)
  Similarity3 alignment;
  AlignmentModel alignment_model = AlignmentModel::kSe3;

  /// per associated pair, in ground-truth time order
  std::vector<double> pair_time_sec;  ///< ground-truth timestamp
  Eigen::Matrix3Xd ground_truth_positions;
  Eigen::Matrix3Xd aligned_estimate_positions;
  std::vector<double> ate_errors_m;
  ErrorStats ate_m;

  /// the whole estimate (every pose, associated or not) after alignment, for plots
  Eigen::Matrix3Xd aligned_estimate_all_positions;

  RpeDelta rpe_delta;
  std::vector<RelativePoseError> rpe;
  ErrorStats rpe_translation_m, rpe_rotation_deg;

  double ground_truth_path_m = 0;  ///< over the associated poses
  double estimate_path_m = 0;      ///< aligned, over the associated poses
  /// ground_truth_path_m / estimate_path_m; NaN (undefined) when the aligned estimate does
  /// not move (estimate_path_m = 0)
  double coverage = 0;
  double scaled_ate_m = 0;  ///< ate_m.rmse / coverage; NaN when coverage is NaN or 0
  TrackedTime tracked;
  /// the frame period the gap limit and expected_poses come from: options.frame_period_sec,
  /// else the ground truth's median sample period, s (0 for a single ground-truth pose)
  double frame_period_sec = 0;
  /// the poses an estimate at frame_period_sec has over the ground truth's span:
  /// round(total_sec / frame_period_sec) + 1 (the ground truth's pose count by default)
  size_t expected_poses = 0;
  /// the associated poses the ATE rests on / expected_poses, in [0, 1]: 3 poses of 41 frames
  /// read 0.073 whatever their errors
  double pose_fraction = 0;

  /// the whole ground truth's path (every pose, associated or not), m
  double ground_truth_full_path_m = 0;
  /// the ground truth's path over the tracked intervals: for consecutive associated poses
  /// whose interval GapIsTracked, the ground-truth polyline between their two poses, m
  double tracked_ground_truth_path_m = 0;
  /// tracked_ground_truth_path_m / ground_truth_full_path_m in [0, 1]; NaN when the ground
  /// truth does not move
  double tracked_path_coverage = 0;
  /// ate_m.rmse / tracked_path_coverage; NaN when that coverage is NaN or 0
  double tracked_scaled_ate_m = 0;
};

/// evaluates `estimate` against `ground_truth` (steps 1-4 above). `ground_truth_name` and
/// `estimate_name` (file paths) name the inputs in errors.
/// @throws ConfigError from options.ValidateOrThrow(); naming the estimate when fewer than 2
///         poses associate (with both time spans and a hint at --max-dt / --offset), and when
///         sim3 alignment meets associated estimated positions that all coincide.
TrajectoryEvaluation EvaluateTrajectory(const Trajectory& ground_truth, const Trajectory& estimate,
                                        const EvaluationOptions& options,
                                        const std::string& ground_truth_name,
                                        const std::string& estimate_name);

/// "none", "se3" or "sim3".
const char* AlignmentModelName(AlignmentModel model);

}  // namespace penumbra
