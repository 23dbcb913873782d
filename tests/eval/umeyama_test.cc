// Umeyama alignment: a known rotation + translation (+ scale) is recovered to < 1e-9 from
// exact correspondences, also where the unconstrained least-squares orthogonal matrix is a
// reflection (coplanar points, mirrored points).
#include "penumbra/eval/umeyama.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

Eigen::Matrix3d RandomRotation(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0, 1);
  return Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized().toRotationMatrix();
}

Eigen::Matrix3Xd RandomPoints(std::mt19937_64& rng, int n, double spread_m) {
  std::uniform_real_distribution<double> u(-spread_m, spread_m);
  Eigen::Matrix3Xd p(3, n);
  for (int k = 0; k < n; ++k) p.col(k) = Eigen::Vector3d(u(rng), u(rng), u(rng));
  return p;
}

// p_A = s R p_B + t, column-wise
Eigen::Matrix3Xd Transform(const Eigen::Matrix3Xd& p_B, double s, const Eigen::Matrix3d& R,
                           const Eigen::Vector3d& t) {
  return ((s * R) * p_B).colwise() + t;
}

double Cost(const Similarity3& X, const Eigen::Matrix3Xd& src, const Eigen::Matrix3Xd& dst) {
  double c = 0;
  for (Eigen::Index k = 0; k < src.cols(); ++k)
    c += (dst.col(k) - X.Apply(src.col(k))).squaredNorm();
  return c;
}

TEST(Umeyama, RecoversRotationAndTranslation) {
  std::mt19937_64 rng(11);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Matrix3d R = RandomRotation(rng);
    const Eigen::Vector3d t = RandomPoints(rng, 1, 50.0).col(0);
    const Eigen::Matrix3Xd src = RandomPoints(rng, 30, 10.0);
    const Similarity3 X = AlignUmeyama(src, Transform(src, 1.0, R, t), false);
    EXPECT_EQ(X.scale, 1.0);
    EXPECT_LT((X.R_AB - R).cwiseAbs().maxCoeff(), 1e-9) << "trial " << trial;
    EXPECT_LT((X.p_AB - t).cwiseAbs().maxCoeff(), 1e-9) << "trial " << trial;
    EXPECT_NEAR(X.R_AB.determinant(), 1.0, 1e-12);
  }
}

TEST(Umeyama, RecoversScaleRotationAndTranslationForSim3) {
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> scale(0.05, 20.0);
  for (int trial = 0; trial < 20; ++trial) {
    const double s = scale(rng);
    const Eigen::Matrix3d R = RandomRotation(rng);
    const Eigen::Vector3d t = RandomPoints(rng, 1, 50.0).col(0);
    const Eigen::Matrix3Xd src = RandomPoints(rng, 25, 5.0);
    const Similarity3 X = AlignUmeyama(src, Transform(src, s, R, t), true);
    EXPECT_LT(std::abs(X.scale - s), 1e-9 * s) << "trial " << trial;
    EXPECT_LT((X.R_AB - R).cwiseAbs().maxCoeff(), 1e-9) << "trial " << trial;
    EXPECT_LT((X.p_AB - t).cwiseAbs().maxCoeff(), 1e-9) << "trial " << trial;
  }
}

// a planar trajectory (a ground robot): Sigma_xy has rank 2 and det(Sigma_xy) = 0, so the sign
// of its third singular vectors is arbitrary and U V^T is a reflection for about half of the
// poses; det(U) det(V) must pick the rotation
TEST(Umeyama, CoplanarPointsGiveTheRotationNotAReflection) {
  std::mt19937_64 rng(13);
  int reflections_avoided = 0;
  for (int trial = 0; trial < 40; ++trial) {
    Eigen::Matrix3Xd src = RandomPoints(rng, 12, 4.0);
    src.row(2).setZero();
    const Eigen::Matrix3d R = RandomRotation(rng);
    const Eigen::Vector3d t(1.0, -2.0, 0.5);
    const double s = trial % 2 == 0 ? 1.0 : 0.3;
    const Eigen::Matrix3Xd dst = Transform(src, s, R, t);
    const Similarity3 X = AlignUmeyama(src, dst, s != 1.0);
    EXPECT_LT((X.R_AB - R).cwiseAbs().maxCoeff(), 1e-9) << "trial " << trial;
    EXPECT_LT((X.p_AB - t).cwiseAbs().maxCoeff(), 1e-9) << "trial " << trial;
    EXPECT_LT(std::abs(X.scale - s), 1e-9) << "trial " << trial;
    // count the configurations where the naive U V^T would have been a reflection
    const Eigen::Vector3d mu_x = src.rowwise().mean(), mu_y = dst.rowwise().mean();
    const Eigen::Matrix3d sigma = (dst.colwise() - mu_y) * (src.colwise() - mu_x).transpose();
    Eigen::JacobiSVD<Eigen::Matrix3d> svd(sigma, Eigen::ComputeFullU | Eigen::ComputeFullV);
    if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0) ++reflections_avoided;
  }
  // the test exercises the reflection case (it would pass vacuously otherwise)
  EXPECT_GT(reflections_avoided, 0);
}

// target = a mirror image of the source: the unconstrained least-squares orthogonal matrix
// U V^T is that reflection (zero error). the result must be a proper rotation, and no nearby
// rotation, scale or translation may do better (a local check of the optimum)
TEST(Umeyama, MirroredPointsGiveTheBestProperRotation) {
  std::mt19937_64 rng(14);
  const Eigen::Matrix3Xd src = RandomPoints(rng, 40, 3.0);
  const Eigen::Matrix3d mirror = Eigen::Vector3d(1, 1, -1).asDiagonal();
  const Eigen::Matrix3d M = RandomRotation(rng) * mirror;  // det -1
  const Eigen::Matrix3Xd dst = Transform(src, 1.0, M, {0.2, 0.4, -1});
  for (bool with_scale : {false, true}) {
    const Similarity3 X = AlignUmeyama(src, dst, with_scale);
    EXPECT_NEAR(X.R_AB.determinant(), 1.0, 1e-12);
    const double best = Cost(X, src, dst);
    // the reflection itself fits exactly; a rotation cannot
    Similarity3 reflection;
    reflection.R_AB = M;
    reflection.p_AB = Eigen::Vector3d(0.2, 0.4, -1);
    EXPECT_LT(Cost(reflection, src, dst), 1e-20);
    EXPECT_GT(best, 1.0);
    std::normal_distribution<double> n(0, 1);
    for (int k = 0; k < 50; ++k) {
      Similarity3 Y = X;
      Y.R_AB = Eigen::AngleAxisd(1e-3, Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized())
                   .toRotationMatrix() *
               X.R_AB;
      EXPECT_GE(Cost(Y, src, dst), best);
      Y = X;
      Y.p_AB += 1e-3 * Eigen::Vector3d(n(rng), n(rng), n(rng));
      EXPECT_GE(Cost(Y, src, dst), best);
      if (with_scale) {
        Y = X;
        Y.scale *= 1.0 + 1e-3 * n(rng);
        EXPECT_GE(Cost(Y, src, dst), best);
      }
    }
  }
}

TEST(Umeyama, RejectsBadInput) {
  const Eigen::Matrix3Xd three = Eigen::Matrix3Xd::Random(3, 3);
  EXPECT_THROW(AlignUmeyama(three, Eigen::Matrix3Xd::Random(3, 4), false), Error);
  EXPECT_THROW(AlignUmeyama(Eigen::Matrix3Xd(3, 0), Eigen::Matrix3Xd(3, 0), false), Error);
  Eigen::Matrix3Xd same(3, 3);
  same.colwise() = Eigen::Vector3d(1, 2, 3);
  try {
    AlignUmeyama(same, three, true);
    FAIL() << "coincident points gave a scale";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("coincide"), std::string::npos) << e.what();
  }
  // without scale, coincident points are a translation
  const Similarity3 X = AlignUmeyama(same, same.colwise() + Eigen::Vector3d(1, 0, 0), false);
  EXPECT_LT((X.p_AB - Eigen::Vector3d(1, 0, 0)).norm(), 1e-12);
  Eigen::Matrix3Xd nan = three;
  nan(1, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(AlignUmeyama(nan, three, false), Error);
}

}  // namespace
}  // namespace penumbra
