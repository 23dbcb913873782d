#include "penumbra/eval/association.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <tuple>

#include "penumbra/core/error.h"

namespace penumbra {

void AssociationOptions::ValidateOrThrow() const {
  if (!(std::isfinite(max_dt_sec) && max_dt_sec > 0))
    throw ConfigError(
        "", 0, "max_dt_sec",
        fmt::format("{} is out of range; expected a finite number > 0 (s)", max_dt_sec));
  if (!std::isfinite(offset_sec))
    throw ConfigError("", 0, "offset_sec",
                      fmt::format("{} is not finite; expected a finite number (s)", offset_sec));
}

Association AssociateTimestamps(const std::vector<double>& ground_truth_time_sec,
                                const std::vector<double>& estimate_time_sec,
                                const AssociationOptions& options) {
  options.ValidateOrThrow();
  const std::vector<double>& a = ground_truth_time_sec;
  const std::vector<double>& b = estimate_time_sec;
  const double max_dt = options.max_dt_sec;
  const double offset = options.offset_sec;

  // candidates (|dt|, gt index, estimate index). b[j] + offset grows with j, so the estimates
  // within the window of a[i] are one run: from the first one not more than max_dt before a[i]
  struct Candidate {
    double dt;
    size_t i, j;
  };
  std::vector<Candidate> candidates;
  for (size_t i = 0; i < a.size(); ++i) {
    size_t j = static_cast<size_t>(std::partition_point(b.begin(), b.end(),
                                                        [&](double tb) {
                                                          return tb + offset < a[i] &&
                                                                 a[i] - (tb + offset) >= max_dt;
                                                        }) -
                                   b.begin());
    for (; j < b.size(); ++j) {
      const double v = b[j] + offset;
      const double dt = std::abs(a[i] - v);
      if (v > a[i] && dt >= max_dt) break;
      if (dt < max_dt) candidates.push_back({dt, i, j});
    }
  }
  // associate.py sorts (|dt|, a, b) tuples; times increase with the index, so indices order alike
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& x, const Candidate& y) {
    return std::tie(x.dt, x.i, x.j) < std::tie(y.dt, y.i, y.j);
  });
  std::vector<bool> used_a(a.size(), false), used_b(b.size(), false);
  Association result;
  for (const Candidate& c : candidates) {
    if (used_a[c.i] || used_b[c.j]) continue;
    used_a[c.i] = used_b[c.j] = true;
    result.pairs.emplace_back(c.i, c.j);
  }
  std::sort(result.pairs.begin(), result.pairs.end());
  result.unmatched_ground_truth = a.size() - result.pairs.size();
  result.unmatched_estimate = b.size() - result.pairs.size();
  return result;
}

}  // namespace penumbra
