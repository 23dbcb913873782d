#include "penumbra/control/quadruped_stance_forces.h"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
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
  // dual form (push-through identity): with B = A S^1/2 ... the minimiser is
  //   f = A^T S^1/2 u,  (alpha I + S^1/2 A A^T S^1/2) u = S^1/2 w,
  // a 6 x 6 SPD system; A A^T = sum over stance feet of [I, [r]x^T; [r]x, [r]x [r]x^T].
  const double sq = std::sqrt(limits.torque_weight);
  Eigen::Matrix<double, 6, 6> K = Eigen::Matrix<double, 6, 6>::Zero();
  for (int i = 0; i < 4; ++i) {
    if (!stance[i]) continue;
    const Eigen::Matrix3d X = Skew(r_W[i]);
    K.block<3, 3>(0, 0).diagonal().array() += 1.0;
    K.block<3, 3>(3, 0) += sq * X;
    K.block<3, 3>(3, 3) += limits.torque_weight * (X * X.transpose());
  }
  K.block<3, 3>(0, 3) = K.block<3, 3>(3, 0).transpose();
  K.diagonal().array() += limits.regularization;
  Eigen::Matrix<double, 6, 1> b = wrench;
  b.tail<3>() *= sq;
  const Eigen::Matrix<double, 6, 1> u = K.llt().solve(b);
  const Eigen::Vector3d u_f = u.head<3>(), u_t = sq * u.tail<3>();
  for (int i = 0; i < 4; ++i) {
    if (!stance[i]) {
      (*forces)[i].setZero();
      continue;
    }
    // A_i^T (u_f, u_t) = u_f + [r_i]x^T u_t = u_f - r_i x u_t
    const Eigen::Vector3d fi = u_f - r_W[i].cross(u_t);
    const double fn_raw = fi.dot(normal_W);
    const double fn = std::clamp(fn_raw, limits.min_normal_n, limits.max_normal_n);
    Eigen::Vector3d ft = fi - fn_raw * normal_W;
    const double ft_norm = ft.norm();
    if (ft_norm > limits.mu * fn) ft *= limits.mu * fn / ft_norm;
    (*forces)[i] = fn * normal_W + ft;
  }
}

}  // namespace penumbra
