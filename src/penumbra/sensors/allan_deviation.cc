#include "penumbra/sensors/allan_deviation.h"

#include <cmath>

namespace penumbra {

std::vector<AllanPoint> OverlappingAllanDeviation(const std::vector<double>& y, double tau0,
                                                  const std::vector<int>& cluster_sizes) {
  const size_t n = y.size();
  std::vector<double> theta(n + 1, 0.0);
  for (size_t i = 0; i < n; ++i) theta[i + 1] = theta[i] + tau0 * y[i];
  std::vector<AllanPoint> out;
  for (int m : cluster_sizes) {
    if (m < 1 || 2 * static_cast<size_t>(m) >= n + 1) continue;
    const size_t terms = n + 1 - 2 * static_cast<size_t>(m);
    double acc = 0;
    for (size_t k = 0; k < terms; ++k) {
      const double d = theta[k + 2 * m] - 2 * theta[k + m] + theta[k];
      acc += d * d;
    }
    const double tau = m * tau0;
    out.push_back({tau, std::sqrt(acc / (2.0 * tau * tau * static_cast<double>(terms)))});
  }
  return out;
}

std::vector<int> LogClusterSizes(size_t n, int per_decade) {
  std::vector<int> m;
  const double top = static_cast<double>(n) / 4.0;
  for (int i = 0;; ++i) {
    const int v =
        static_cast<int>(std::lround(std::pow(10.0, static_cast<double>(i) / per_decade)));
    if (v > top) break;
    if (m.empty() || v != m.back()) m.push_back(v);
  }
  return m;
}

}  // namespace penumbra
