#pragma once
// least-squares alignment of two point sets: S. Umeyama, "Least-squares estimation of
// transformation parameters between two point patterns", IEEE TPAMI 13(4):376-380, 1991.
//
// given points x_i (source) and y_i (target), i = 1..n, it finds the rotation R (det R = +1,
// never a reflection), translation t and, for a similarity, scale c > 0 minimising
//   e^2 = 1/n sum_i |y_i - (c R x_i + t)|^2.
// with mu_x, mu_y the means, sigma_x^2 = 1/n sum |x_i - mu_x|^2 and the cross-covariance
// Sigma_xy = 1/n sum (y_i - mu_y)(x_i - mu_x)^T = U D V^T (SVD):
//   S = diag(1, 1, det(U) det(V)),  R = U S V^T,  c = tr(D S) / sigma_x^2,  t = mu_y - c R mu_x.
// taking the sign from det(U) det(V) (not det(Sigma_xy)) is the paper's rule for both the full
// rank case and rank(Sigma_xy) = 2 (coplanar points, where det(Sigma_xy) = 0); it is what keeps
// R a rotation when the unconstrained optimum U V^T would be a reflection.
// for rank(Sigma_xy) <= 1 (collinear or coincident points) the minimiser is not unique; one of
// the minimisers is returned.

#include <Eigen/Core>

namespace penumbra {

/// a similarity transform p_A = scale * R_AB * p_B + p_AB (a rigid transform when scale = 1).
struct Similarity3 {
  double scale = 1.0;
  Eigen::Matrix3d R_AB = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p_AB = Eigen::Vector3d::Zero();  ///< m, in frame A

  /// the point p_B (m) expressed in A.
  Eigen::Vector3d Apply(const Eigen::Vector3d& p_B) const { return scale * (R_AB * p_B) + p_AB; }
};

/// which transform an alignment may use.
enum class AlignmentModel {
  kNone,  ///< identity: the estimate is compared as it is
  kSe3,   ///< rotation + translation (Umeyama with c = 1)
  kSim3,  ///< rotation + translation + scale (monocular estimates)
};

/// Umeyama's least-squares transform taking `source_B` onto `target_A` (3 x n each, the same
/// n >= 1; columns are corresponding points in frames B and A, m). with_scale = false fixes
/// scale = 1 (R and t as above with c = 1).
/// @throws Error if the sizes differ, n = 0, a coordinate is not finite, or with_scale and
///         the source points all coincide (sigma_x^2 = 0: no scale is defined).
Similarity3 AlignUmeyama(const Eigen::Matrix3Xd& source_B, const Eigen::Matrix3Xd& target_A,
                         bool with_scale);

}  // namespace penumbra
