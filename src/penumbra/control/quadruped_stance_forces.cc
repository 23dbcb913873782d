#include "penumbra/control/quadruped_stance_forces.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

namespace penumbra {
namespace {

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

}  // namespace

void DistributeStanceForces(const std::array<Eigen::Vector3d, 4>& r_W,
                            const std::array<bool, 4>& stance,
                            const Eigen::Matrix<double, 6, 1>& wrench,
                            const Eigen::Vector3d& normal_W, const StanceForceLimits& limits,
                            std::array<Eigen::Vector3d, 4>* forces) {
  // A (6 x 12), swing feet's columns zero so their forces come out zero
  Eigen::Matrix<double, 6, 12> A = Eigen::Matrix<double, 6, 12>::Zero();
  for (int i = 0; i < 4; ++i) {
    if (!stance[i]) continue;
    A.block<3, 3>(0, 3 * i).setIdentity();
    A.block<3, 3>(3, 3 * i) = Skew(r_W[i]);
  }
  Eigen::Matrix<double, 6, 1> s;
  s << 1, 1, 1, limits.torque_weight, limits.torque_weight, limits.torque_weight;
  const Eigen::Matrix<double, 12, 6> AtS = A.transpose() * s.asDiagonal();
  Eigen::Matrix<double, 12, 12> H = AtS * A;
  H.diagonal().array() += limits.regularization;
  const Eigen::Matrix<double, 12, 1> f = H.ldlt().solve(AtS * wrench);
  for (int i = 0; i < 4; ++i) {
    if (!stance[i]) {
      (*forces)[i].setZero();
      continue;
    }
    const Eigen::Vector3d fi = f.segment<3>(3 * i);
    const double fn_raw = fi.dot(normal_W);
    const double fn = std::clamp(fn_raw, limits.min_normal_n, limits.max_normal_n);
    Eigen::Vector3d ft = fi - fn_raw * normal_W;
    const double ft_norm = ft.norm();
    if (ft_norm > limits.mu * fn) ft *= limits.mu * fn / ft_norm;
    (*forces)[i] = fn * normal_W + ft;
  }
}

}  // namespace penumbra
