// exact ray intersection with the quadric primitives.

#include "penumbra/render/analytic_shapes.h"

#include <gtest/gtest.h>

#include <cmath>

#include "penumbra/core/rng.h"

namespace penumbra {
namespace {

AnalyticShape Shape(AnalyticKind k, Eigen::Vector3d size) {
  AnalyticShape s;
  s.kind = k;
  s.size = size;
  return s;
}

// signed distance-like residual of a point from the shape's surface (0 on it).
double Residual(const AnalyticShape& s, const Eigen::Vector3d& p) {
  const double r = s.size.x(), h = s.size.y();
  switch (s.kind) {
    case AnalyticKind::kPlane:
      return std::abs(p.z());
    case AnalyticKind::kSphere:
      return std::abs(p.norm() - r);
    case AnalyticKind::kEllipsoid:
      return std::abs(p.cwiseQuotient(s.size).norm() - 1);
    case AnalyticKind::kCylinder: {
      const double rho = std::hypot(p.x(), p.y());
      if (std::abs(p.z()) <= h + 1e-12 && std::abs(rho - r) < 1e-9) return 0;
      return rho <= r + 1e-12 ? std::abs(std::abs(p.z()) - h) : 1;
    }
    case AnalyticKind::kCapsule: {
      const double z = std::clamp(p.z(), -h, h);
      return std::abs((p - Eigen::Vector3d(0, 0, z)).norm() - r);
    }
  }
  return 1;
}

TEST(AnalyticShapesTest, KnownHits) {
  double t;
  ShapePart part;
  const Eigen::Vector3d o(-5, 0, 0), dx(1, 0, 0);
  ASSERT_TRUE(IntersectAnalytic(Shape(AnalyticKind::kSphere, {1, 0, 0}), o, dx, 0, 1e9, &t, &part));
  EXPECT_DOUBLE_EQ(t, 4);
  // unnormalised direction: t in units of |d|.
  ASSERT_TRUE(
      IntersectAnalytic(Shape(AnalyticKind::kSphere, {1, 0, 0}), o, 2 * dx, 0, 1e9, &t, &part));
  EXPECT_DOUBLE_EQ(t, 2);
  // from inside: the far side.
  ASSERT_TRUE(
      IntersectAnalytic(Shape(AnalyticKind::kSphere, {1, 0, 0}), {0, 0, 0}, dx, 0, 1e9, &t, &part));
  EXPECT_DOUBLE_EQ(t, 1);
  // tmax before the surface: no hit; tmin past the near side: the far side.
  EXPECT_FALSE(
      IntersectAnalytic(Shape(AnalyticKind::kSphere, {1, 0, 0}), o, dx, 0, 3.9, &t, &part));
  ASSERT_TRUE(
      IntersectAnalytic(Shape(AnalyticKind::kSphere, {1, 0, 0}), o, dx, 4.5, 1e9, &t, &part));
  EXPECT_DOUBLE_EQ(t, 6);
  // capsule along z seen along z: the hemisphere tip at h + r.
  ASSERT_TRUE(IntersectAnalytic(Shape(AnalyticKind::kCapsule, {0.2, 0.5, 0}), {0, 0, 3}, {0, 0, -1},
                                0, 1e9, &t, &part));
  EXPECT_DOUBLE_EQ(t, 3 - 0.7);
  EXPECT_EQ(part, ShapePart::kTop);
  // cylinder: cap from above, side from the side.
  ASSERT_TRUE(IntersectAnalytic(Shape(AnalyticKind::kCylinder, {0.2, 0.5, 0}), {0.1, 0, 3},
                                {0, 0, -1}, 0, 1e9, &t, &part));
  EXPECT_DOUBLE_EQ(t, 2.5);
  EXPECT_EQ(part, ShapePart::kTop);
  ASSERT_TRUE(IntersectAnalytic(Shape(AnalyticKind::kCylinder, {0.2, 0.5, 0}), {-3, 0, 0.4}, dx, 0,
                                1e9, &t, &part));
  EXPECT_DOUBLE_EQ(t, 2.8);
  EXPECT_EQ(part, ShapePart::kMain);
  // just outside the cylinder's cap radius: miss.
  EXPECT_FALSE(IntersectAnalytic(Shape(AnalyticKind::kCylinder, {0.2, 0.5, 0}), {0.21, 0, 3},
                                 {0, 0, -1}, 0, 1e9, &t, &part));
  // ellipsoid along its y axis.
  ASSERT_TRUE(IntersectAnalytic(Shape(AnalyticKind::kEllipsoid, {0.1, 0.7, 0.3}), {0, -4, 0},
                                {0, 1, 0}, 0, 1e9, &t, &part));
  EXPECT_DOUBLE_EQ(t, 3.3);
  // finite plane: inside and outside its rectangle.
  ASSERT_TRUE(IntersectAnalytic(Shape(AnalyticKind::kPlane, {1, 2, 0}), {0.9, 1.9, 1}, {0, 0, -1},
                                0, 1e9, &t, &part));
  EXPECT_DOUBLE_EQ(t, 1);
  EXPECT_FALSE(IntersectAnalytic(Shape(AnalyticKind::kPlane, {1, 2, 0}), {1.1, 0, 1}, {0, 0, -1}, 0,
                                 1e9, &t, &part));
}

TEST(AnalyticShapesTest, RandomHitsLieOnTheSurfaceWithOutwardNormals) {
  const AnalyticShape shapes[] = {
      Shape(AnalyticKind::kSphere, {0.4, 0, 0}), Shape(AnalyticKind::kEllipsoid, {0.2, 0.5, 0.3}),
      Shape(AnalyticKind::kCylinder, {0.3, 0.6, 0}), Shape(AnalyticKind::kCapsule, {0.25, 0.4, 0})};
  Rng rng(1);
  for (const AnalyticShape& s : shapes) {
    int hits = 0;
    for (int k = 0; k < 3000; ++k) {
      // rays from a sphere of radius 3 towards random points near the shape.
      const Eigen::Vector3d o =
          3 * Eigen::Vector3d(rng.UniformD() - 0.5, rng.UniformD() - 0.5, rng.UniformD() - 0.5)
                  .normalized();
      const Eigen::Vector3d target(rng.UniformD() - 0.5, rng.UniformD() - 0.5,
                                   2 * rng.UniformD() - 1);
      const Eigen::Vector3d d = (target - o) * (0.5 + rng.UniformD());
      double t;
      ShapePart part;
      if (!IntersectAnalytic(s, o, d, 0, 1e9, &t, &part)) continue;
      ++hits;
      const Eigen::Vector3d p = o + t * d;
      EXPECT_LT(Residual(s, p), 1e-9);
      const Eigen::Vector3d n = AnalyticNormal(s, p, part);
      EXPECT_NEAR(n.norm(), 1.0, 1e-12);
      EXPECT_LE(n.dot(d), 1e-12);  // rays from outside meet the outward side
      // nothing nearer: a point slightly before the hit is outside (the ray was outside).
      EXPECT_FALSE(IntersectAnalytic(s, o, d, 0, t * (1 - 1e-9), &t, &part));
    }
    EXPECT_GT(hits, 300);
  }
}

TEST(AnalyticShapesTest, HalfExtents) {
  EXPECT_EQ(AnalyticHalfExtents(Shape(AnalyticKind::kCapsule, {0.1, 0.5, 0})),
            Eigen::Vector3d(0.1, 0.1, 0.6));
  EXPECT_EQ(AnalyticHalfExtents(Shape(AnalyticKind::kCylinder, {0.1, 0.5, 0})),
            Eigen::Vector3d(0.1, 0.1, 0.5));
  EXPECT_EQ(AnalyticHalfExtents(Shape(AnalyticKind::kPlane, {2, 3, 0})), Eigen::Vector3d(2, 3, 0));
}

}  // namespace
}  // namespace penumbra
