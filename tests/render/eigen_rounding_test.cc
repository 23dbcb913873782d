// the shared scalar formulas that replaced Eigen code round as Eigen does
// (render/light/bsdf_math.h's EigenDot, render/light/light_math.h's DotAs<true>,
// render/light/emitter_math.h's EmitterDot, EmitterNormalize, PoseApply and RotateApply): checked
// bit for bit against Eigen on random inputs, so that a change of Eigen or of the compiler that
// moves its rounding (and with it the CPU's pathtraced images, which these formulas must keep)
// fails here first.

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstring>
#include <random>

#include "penumbra/core/pose.h"
#include "penumbra/render/light/bsdf_math.h"
#include "penumbra/render/light/emitter_math.h"
#include "penumbra/render/light/light_math.h"

namespace penumbra {
namespace {

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }
bool SameBits(float a, float b) { return std::memcmp(&a, &b, sizeof(float)) == 0; }

TEST(EigenRounding, FloatDotProductsAreEigens) {
  std::mt19937 g(1);
  std::uniform_real_distribution<float> U(-3, 3);
  int differ = 0;
  for (int i = 0; i < 100000; ++i) {
    const Eigen::Vector3f a(U(g), U(g), U(g)), b(U(g), U(g), U(g));
    const Float3 fa{a.x(), a.y(), a.z()}, fb{b.x(), b.y(), b.z()};
    differ += !SameBits(a.dot(b), EigenDot(fa, fb));
    differ += !SameBits(a.squaredNorm(), DotAs<true, float>(fa, fa));
  }
  EXPECT_EQ(differ, 0);
}

TEST(EigenRounding, DoubleVectorsAndPosesAreEigens) {
  std::mt19937 g(2);
  std::uniform_real_distribution<double> U(-3, 3);
  int differ = 0;
  for (int i = 0; i < 100000; ++i) {
    Pose X = Pose::Identity();
    X.linear() =
        Eigen::AngleAxisd(U(g), Eigen::Vector3d(U(g), U(g), U(g)).normalized()).toRotationMatrix();
    X.translation() = Eigen::Vector3d(U(g), U(g), U(g));
    const Eigen::Vector3d a(U(g), U(g), U(g)), b(U(g), U(g), U(g));
    double R[9], t[3];
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) R[3 * r + c] = X.linear()(r, c);
      t[r] = X.translation()[r];
    }
    const Eigen::Vector3d q = X * a, v = X.linear() * a, n = a.normalized();
    double pq[3], rv[3], na[3];
    PoseApply(R, t, a.data(), pq);
    RotateApply(R, a.data(), rv);
    EmitterNormalize(a.data(), na);
    for (int k = 0; k < 3; ++k)
      differ += !SameBits(q[k], pq[k]) + !SameBits(v[k], rv[k]) + !SameBits(n[k], na[k]);
    differ += !SameBits(a.dot(b), EmitterDot(a.data(), b.data()));
  }
  EXPECT_EQ(differ, 0);
}

}  // namespace
}  // namespace penumbra
