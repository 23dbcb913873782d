#pragma once
// overlapping Allan deviation of a rate signal (IEEE Std 952-1997, Annex C; Riley, NIST
// Special Publication 1065 "Handbook of Frequency Stability Analysis", 2008, eq. 12 in
// terms of the integrated signal theta):
//   AVAR(tau = m tau0) = 1 / (2 tau^2 (N - 2m)) sum_{k=0}^{N-2m-1} (theta_{k+2m} - 2 theta_{k+m}
//   + theta_k)^2,  theta_k = tau0 sum_{i<k} y_i.

#include <cstddef>
#include <vector>

namespace penumbra {

/// one point of an Allan deviation curve.
struct AllanPoint {
  double tau_sec = 0;
  double adev = 0;  ///< same unit as the signal
};

/// overlapping ADEV of `y` (sample period tau0_sec) at cluster sizes m (tau = m tau0).
/// cluster sizes with 2m >= y.size() are skipped.
std::vector<AllanPoint> OverlappingAllanDeviation(const std::vector<double>& y, double tau0_sec,
                                                  const std::vector<int>& cluster_sizes);

/// cluster sizes spaced logarithmically (`per_decade` per decade) from 1 to n / 4.
std::vector<int> LogClusterSizes(std::size_t n, int per_decade = 10);

}  // namespace penumbra
