#include "penumbra/scene/sim_time.h"

#include <cmath>
#include <limits>

namespace penumbra {

double PhysicsRateHz(double timestep_sec) {
  const double rate = 1.0 / timestep_sec;
  const double r = std::nearbyint(rate);
  return r >= 1 && std::abs(rate - r) <= 1e-9 * r ? r : rate;
}

double SimTimeOfStep(int64_t n, double timestep_sec) {
  if (n <= 0) return 0.0;
  const double nd = static_cast<double>(n);
  const double rate = PhysicsRateHz(timestep_sec);
  constexpr double kInf = std::numeric_limits<double>::infinity();
  if (rate == std::nearbyint(rate)) {
    // n / R rounded up: fma gives the sign of q R - n exactly
    double q = nd / rate;
    if (std::fma(q, rate, -nd) < 0) q = std::nextafter(q, kInf);
    return q;
  }
  double p = nd * timestep_sec;
  if (std::fma(nd, timestep_sec, -p) > 0) p = std::nextafter(p, kInf);
  return p;
}

}  // namespace penumbra
