#pragma once
// the error measures of trajectory evaluation, on poses already associated in time (pose k of
// one sequence belongs with pose k of the other):
// - absolute trajectory error (ATE; Sturm et al., "A Benchmark for the Evaluation of RGB-D
//   SLAM Systems", IROS 2012, sec. VI-B): |p_gt,k - p_est,k| after alignment, per pose;
// - relative pose error (RPE; same paper, sec. VI-A): for pose pairs (i, j) a fixed interval
//   apart, E_ij = (Q_i^-1 Q_j)^-1 (P_i^-1 P_j) with Q the ground truth and P the estimate;
//   its translation norm (m) and rotation angle (deg);
// - path length, and the fraction of ground-truth time tracked (docs/evaluation.md).

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "penumbra/core/pose.h"

namespace penumbra {

/// summary statistics of a list of errors (all in the errors' unit). empty input: count 0,
/// every other field NaN.
struct ErrorStats {
  size_t count = 0;
  double rmse = 0;    ///< sqrt(mean(e^2))
  double mean = 0;    ///< mean(e)
  double median = 0;  ///< middle value; the mean of the two middle values for an even count
  double std = 0;     ///< population standard deviation sqrt(mean((e - mean)^2)) (numpy.std)
  double min = 0;
  double max = 0;
};

/// the statistics of `errors`.
ErrorStats SummarizeErrors(const std::vector<double>& errors);

/// length of the polyline through `positions` (3 x n, m): sum of |p_k+1 - p_k|; 0 for n < 2.
double PathLength(const Eigen::Matrix3Xd& positions);

/// per-pose translational error |ground_truth_k - estimate_k| (m) of two 3 x n position sets
/// in the same frame (the estimate already aligned).
/// @throws Error if the sizes differ.
std::vector<double> AbsoluteTranslationErrors(const Eigen::Matrix3Xd& ground_truth,
                                              const Eigen::Matrix3Xd& estimate);

/// the interval of the RPE. exactly one of `frames` (an index step in the associated
/// sequence, >= 1) or `seconds` (> 0) is used: `seconds` when set.
struct RpeDelta {
  int64_t frames = 1;
  std::optional<double> seconds;

  /// @throws ConfigError (key "delta" / "delta_sec") for frames < 1 or seconds not finite > 0.
  void ValidateOrThrow() const;
};

/// the relative pose error of one pose pair (i, j), i < j.
struct RelativePoseError {
  size_t i = 0, j = 0;       ///< indices into the associated sequence
  double translation_m = 0;  ///< |translation of E_ij|, m
  double rotation_deg = 0;   ///< rotation angle of E_ij in [0, 180], deg
};

/// RPE of associated poses X_W_gt[k], X_V_est[k] taken at time_sec[k] (strictly increasing).
/// pairs: frames: (k, k + frames) for every k with k + frames < n. seconds: for each k the
/// pose j whose time is nearest to time_sec[k] + seconds (the earlier one on a tie); the pair
/// is used when j > k and |time_sec[j] - (time_sec[k] + seconds)| < max_dt_sec, so no pair
/// spans a gap of the wrong length.
/// @throws Error if the three sequences differ in length.
std::vector<RelativePoseError> RelativePoseErrors(const std::vector<double>& time_sec,
                                                  const std::vector<Pose>& X_W_gt,
                                                  const std::vector<Pose>& X_V_est,
                                                  const RpeDelta& delta, double max_dt_sec);

/// relative tolerance of the gap limit: an interval counts as tracked when it is at most
/// max_gap_sec * (1 + kTrackedGapRelTolerance). timestamps are decimal numbers held in binary
/// doubles, so an interval of exactly 3 sample periods (two lost frames) and the default limit
/// of 3 x the median period differ by rounding alone (e.g. 4.9 - 4.6 = 0.3000000000000007 s
/// against 3 x (4.4 - 4.3) = 0.29999999999999893 s); 1e-9 is far above that rounding (about
/// 1e-15 relative) and far below a real extra frame (1/3 relative). docs/evaluation.md.
inline constexpr double kTrackedGapRelTolerance = 1e-9;

/// the default gap limit in frame periods: an interval of up to 3 periods (at most two lost
/// frames, or a pose that association jitter moved by up to a period) counts as tracked. the
/// period is the ground truth's (or the caller's frame period), never the estimate's own
/// spacing, which for a mostly lost estimate is itself a gap (docs/evaluation.md).
inline constexpr double kTrackedGapPeriods = 3.0;

/// true when an interval of `gap_sec` between consecutive associated poses counts as tracked
/// under the limit `max_gap_sec`: gap_sec <= max_gap_sec * (1 + kTrackedGapRelTolerance).
bool GapIsTracked(double gap_sec, double max_gap_sec);

/// how much of the ground truth's time span the estimate tracked.
struct TrackedTime {
  double tracked_sec = 0;  ///< sum of the intervals between consecutive associated poses that
                           ///< GapIsTracked
  double total_sec = 0;    ///< last minus first ground-truth timestamp
  double fraction = 0;     ///< tracked_sec / total_sec (NaN when total_sec is 0)
  double max_gap_sec = 0;  ///< the gap limit used
};

/// tracked time: with tau_1 < ... < tau_K the ground-truth times of the associated poses,
/// tracked = sum over k of (tau_k+1 - tau_k) for the intervals with GapIsTracked(tau_k+1 -
/// tau_k, max_gap_sec) (longer ones are tracking losses); total = ground_truth_end_sec -
/// ground_truth_start_sec.
TrackedTime ComputeTrackedTime(const std::vector<double>& associated_time_sec,
                               double ground_truth_start_sec, double ground_truth_end_sec,
                               double max_gap_sec);

/// median of the differences of consecutive values of `time_sec` (its typical sample
/// period, s); 0 for fewer than 2 values.
double MedianPeriod(const std::vector<double>& time_sec);

}  // namespace penumbra
