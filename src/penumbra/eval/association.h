#pragma once
// timestamp association of two trajectories, the rule of the TUM RGB-D benchmark's
// associate.py (Sturm et al. 2012): every pair (ground-truth pose a, estimated pose b) with
// |t_a - (t_b + offset)| < max_dt is a candidate; candidates are taken greedily from the
// smallest |dt| up (ties: earlier ground-truth time, then earlier estimate time), and a pair is
// kept only while neither of its poses is used yet, so each pose is used at most once.

#include <cstddef>
#include <utility>
#include <vector>

namespace penumbra {

/// the association window.
struct AssociationOptions {
  /// largest time difference of a pair, s (exclusive: |dt| < max_dt_sec); TUM's default 0.02
  double max_dt_sec = 0.02;
  /// added to every estimate timestamp before comparing, s (associate.py's --offset)
  double offset_sec = 0.0;

  /// @throws ConfigError (key "max_dt_sec" / "offset_sec") unless max_dt_sec is finite and > 0
  ///         and offset_sec is finite.
  void ValidateOrThrow() const;
};

/// the outcome of AssociateTimestamps.
struct Association {
  /// (ground-truth index, estimate index) of each pair, sorted by ground-truth index
  std::vector<std::pair<size_t, size_t>> pairs;
  size_t unmatched_ground_truth = 0;  ///< ground-truth poses in no pair
  size_t unmatched_estimate = 0;      ///< estimated poses in no pair
};

/// associates ground-truth times with estimate times (both strictly increasing, s) by the
/// greedy nearest-neighbour rule above. runs in O((n + m + c) log c) for c candidates.
/// @throws ConfigError from options.ValidateOrThrow().
Association AssociateTimestamps(const std::vector<double>& ground_truth_time_sec,
                                const std::vector<double>& estimate_time_sec,
                                const AssociationOptions& options);

}  // namespace penumbra
