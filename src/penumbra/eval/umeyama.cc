#include "penumbra/eval/umeyama.h"

#include <fmt/format.h>

#include <Eigen/LU>
#include <Eigen/SVD>

#include "penumbra/core/error.h"

namespace penumbra {

Similarity3 AlignUmeyama(const Eigen::Matrix3Xd& source_B, const Eigen::Matrix3Xd& target_A,
                         bool with_scale) {
  const Eigen::Index n = source_B.cols();
  if (n != target_A.cols())
    throw Error(
        fmt::format("AlignUmeyama: {} source points but {} target points; expected the "
                    "same number",
                    n, target_A.cols()));
  if (n == 0) throw Error("AlignUmeyama: no points; expected at least 1");
  if (!source_B.allFinite() || !target_A.allFinite())
    throw Error("AlignUmeyama: a coordinate is not finite; expected finite points");

  const Eigen::Vector3d mu_x = source_B.rowwise().mean();
  const Eigen::Vector3d mu_y = target_A.rowwise().mean();
  const Eigen::Matrix3Xd x = source_B.colwise() - mu_x;
  const Eigen::Matrix3Xd y = target_A.colwise() - mu_y;
  const double inv_n = 1.0 / static_cast<double>(n);
  const double sigma_x2 = x.squaredNorm() * inv_n;
  const Eigen::Matrix3d sigma_xy = (y * x.transpose()) * inv_n;

  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(sigma_xy, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Matrix3d& u = svd.matrixU();
  const Eigen::Matrix3d& v = svd.matrixV();
  Eigen::Vector3d s(1.0, 1.0, 1.0);
  if (u.determinant() * v.determinant() < 0) s(2) = -1.0;

  Similarity3 out;
  out.R_AB = u * s.asDiagonal() * v.transpose();
  if (with_scale) {
    if (!(sigma_x2 > 0))
      throw Error(
          "AlignUmeyama: the source points all coincide; expected points spread in space for a "
          "scale (sim3)");
    out.scale = svd.singularValues().dot(s) / sigma_x2;
  }
  out.p_AB = mu_y - out.scale * (out.R_AB * mu_x);
  return out;
}

}  // namespace penumbra
