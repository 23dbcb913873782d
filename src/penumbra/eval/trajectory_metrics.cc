#include "penumbra/eval/trajectory_metrics.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

double Median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  const size_t h = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(h), v.end());
  const double upper = v[h];
  if (v.size() % 2 == 1) return upper;
  const double lower = *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(h));
  return 0.5 * (lower + upper);
}

// rotation angle of R in [0, pi]: through the quaternion (Eigen: 2 atan2(|v|, |w|)), which
// stays accurate near 0 and pi where acos((tr R - 1) / 2) does not
double RotationAngleRad(const Eigen::Matrix3d& R) {
  return Eigen::AngleAxisd(Eigen::Quaterniond(R).normalized()).angle();
}

}  // namespace

ErrorStats SummarizeErrors(const std::vector<double>& errors) {
  ErrorStats s;
  s.count = errors.size();
  if (errors.empty()) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    s.rmse = s.mean = s.median = s.std = s.min = s.max = nan;
    return s;
  }
  const double n = static_cast<double>(errors.size());
  double sum = 0, sum_sq = 0;
  for (double e : errors) sum += e, sum_sq += e * e;
  s.mean = sum / n;
  s.rmse = std::sqrt(sum_sq / n);
  double dev_sq = 0;
  for (double e : errors) dev_sq += (e - s.mean) * (e - s.mean);
  s.std = std::sqrt(dev_sq / n);
  s.median = Median(errors);
  const auto [lo, hi] = std::minmax_element(errors.begin(), errors.end());
  s.min = *lo;
  s.max = *hi;
  return s;
}

double PathLength(const Eigen::Matrix3Xd& positions) {
  double length = 0;
  for (Eigen::Index k = 1; k < positions.cols(); ++k)
    length += (positions.col(k) - positions.col(k - 1)).norm();
  return length;
}

std::vector<double> AbsoluteTranslationErrors(const Eigen::Matrix3Xd& ground_truth,
                                              const Eigen::Matrix3Xd& estimate) {
  if (ground_truth.cols() != estimate.cols())
    throw Error(
        fmt::format("AbsoluteTranslationErrors: {} ground-truth but {} estimated "
                    "positions; expected the same number",
                    ground_truth.cols(), estimate.cols()));
  std::vector<double> e(static_cast<size_t>(ground_truth.cols()));
  for (Eigen::Index k = 0; k < ground_truth.cols(); ++k)
    e[static_cast<size_t>(k)] = (ground_truth.col(k) - estimate.col(k)).norm();
  return e;
}

void RpeDelta::ValidateOrThrow() const {
  if (seconds) {
    if (!(std::isfinite(*seconds) && *seconds > 0))
      throw ConfigError(
          "", 0, "delta_sec",
          fmt::format("{} is out of range; expected a finite number > 0 (s)", *seconds));
  } else if (frames < 1) {
    throw ConfigError("", 0, "delta",
                      fmt::format("{} is out of range; expected an integer >= 1 (frames)", frames));
  }
}

std::vector<RelativePoseError> RelativePoseErrors(const std::vector<double>& time_sec,
                                                  const std::vector<Pose>& X_W_gt,
                                                  const std::vector<Pose>& X_V_est,
                                                  const RpeDelta& delta, double max_dt_sec) {
  delta.ValidateOrThrow();
  const size_t n = time_sec.size();
  if (X_W_gt.size() != n || X_V_est.size() != n)
    throw Error(
        fmt::format("RelativePoseErrors: {} times, {} ground-truth and {} estimated "
                    "poses; expected the same number",
                    n, X_W_gt.size(), X_V_est.size()));
  std::vector<RelativePoseError> out;
  for (size_t i = 0; i < n; ++i) {
    size_t j = 0;
    if (delta.seconds) {
      const double target = time_sec[i] + *delta.seconds;
      const size_t hi = static_cast<size_t>(
          std::lower_bound(time_sec.begin(), time_sec.end(), target) - time_sec.begin());
      // nearest of hi - 1 and hi; the earlier on a tie
      j = hi;
      if (hi == n || (hi > 0 && target - time_sec[hi - 1] <= time_sec[hi] - target)) j = hi - 1;
      if (j <= i || !(std::abs(time_sec[j] - target) < max_dt_sec)) continue;
    } else {
      if (static_cast<uint64_t>(delta.frames) >= n - i) break;
      j = i + static_cast<size_t>(delta.frames);
    }
    const Pose gt_ij = X_W_gt[i].inverse(Eigen::Isometry) * X_W_gt[j];
    const Pose est_ij = X_V_est[i].inverse(Eigen::Isometry) * X_V_est[j];
    const Pose E = gt_ij.inverse(Eigen::Isometry) * est_ij;
    RelativePoseError r;
    r.i = i;
    r.j = j;
    r.translation_m = E.translation().norm();
    r.rotation_deg = RotationAngleRad(E.linear()) * 180.0 / std::numbers::pi;
    out.push_back(r);
  }
  return out;
}

bool GapIsTracked(double gap_sec, double max_gap_sec) {
  return gap_sec <= max_gap_sec * (1.0 + kTrackedGapRelTolerance);
}

TrackedTime ComputeTrackedTime(const std::vector<double>& associated_time_sec,
                               double ground_truth_start_sec, double ground_truth_end_sec,
                               double max_gap_sec) {
  TrackedTime t;
  t.max_gap_sec = max_gap_sec;
  t.total_sec = ground_truth_end_sec - ground_truth_start_sec;
  for (size_t k = 1; k < associated_time_sec.size(); ++k) {
    const double gap = associated_time_sec[k] - associated_time_sec[k - 1];
    if (GapIsTracked(gap, max_gap_sec)) t.tracked_sec += gap;
  }
  t.fraction =
      t.total_sec > 0 ? t.tracked_sec / t.total_sec : std::numeric_limits<double>::quiet_NaN();
  return t;
}

double MedianPeriod(const std::vector<double>& time_sec) {
  if (time_sec.size() < 2) return 0;
  std::vector<double> d(time_sec.size() - 1);
  for (size_t k = 1; k < time_sec.size(); ++k) d[k - 1] = time_sec[k] - time_sec[k - 1];
  return Median(std::move(d));
}

}  // namespace penumbra
