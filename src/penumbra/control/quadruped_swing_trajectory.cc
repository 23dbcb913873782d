#include "penumbra/control/quadruped_swing_trajectory.h"

#include <algorithm>
#include <cmath>

namespace penumbra {

SwingSample CycloidSwing(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, double height_m,
                         double s, double duration_sec) {
  s = std::clamp(s, 0.0, 1.0);
  const double w = 2 * M_PI * s;
  const double sigma = s - std::sin(w) / (2 * M_PI);
  const double dsigma = 1 - std::cos(w);  // d sigma / ds
  const Eigen::Vector3d d = p1 - p0;
  SwingSample out;
  out.p = p0 + d * sigma;
  out.p.z() += height_m * (1 - std::cos(w)) / 2;
  out.v = d * (dsigma / duration_sec);
  out.v.z() += height_m * M_PI * std::sin(w) / duration_sec;
  return out;
}

}  // namespace penumbra
