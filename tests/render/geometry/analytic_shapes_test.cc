// exact ray intersection with the quadric primitives.

#include "penumbra/render/geometry/analytic_shapes.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <vector>

#include "penumbra/core/rng.h"
#include "penumbra/render/embree/analytic_lanes.h"

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

// ---- IntersectAnalyticLanes (the batched, vectorised path) against IntersectAnalytic ----

// without fused multiply-adds (this project's -ffp-contract=off on a target without FMA
// instructions) the lane kernels perform IntersectAnalytic's operations in its order: t must
// then match bit for bit. with FMA instructions Eigen's own kernels may fuse, so t may differ
// in the last bits: 1e-12 relative.
#if defined(__FMA__)
constexpr bool kBitwise = false;
#else
constexpr bool kBitwise = true;
#endif

struct TestRay {
  Eigen::Vector3d o, d;
  double tmin = 0, tmax = std::numeric_limits<double>::infinity();
};

Eigen::Vector3d RandomUnit(Rng* rng) {
  for (;;) {
    const Eigen::Vector3d v(2 * rng->UniformD() - 1, 2 * rng->UniformD() - 1,
                            2 * rng->UniformD() - 1);
    const double n = v.norm();
    if (n > 1e-3 && n <= 1) return v / n;
  }
}

// rays of every kind that matters for `s` (extent e): random lines near it, rays at random
// points near it (mostly hits), rays starting inside, rays along and across its axis (caps, the
// capsule's tips and hemispheres), rays parallel to z = 0 (no cap or plane hit), rays tangent
// to the side or sphere to within 1e-9 of the radius on either side, rays with a finite tmax
// or a tmin past the near side, and rays with non-unit directions.
std::vector<TestRay> RaysFor(const AnalyticShape& s, Rng* rng) {
  const Eigen::Vector3d e = AnalyticHalfExtents(s) + Eigen::Vector3d::Constant(1e-3);
  const double r = s.size.x(), h = s.size.y();
  auto point_near = [&](double scale) {
    return Eigen::Vector3d((2 * rng->UniformD() - 1) * e.x() * scale,
                           (2 * rng->UniformD() - 1) * e.y() * scale,
                           (2 * rng->UniformD() - 1) * e.z() * scale);
  };
  std::vector<TestRay> rays;
  for (int k = 0; k < 4000; ++k) {
    TestRay ray;
    const double len = 0.25 + 4 * rng->UniformD();  // |d|
    switch (k % 10) {
      case 0:  // random line through the neighbourhood
        ray.o = point_near(3);
        ray.d = RandomUnit(rng) * len;
        break;
      case 1:
      case 2:  // from outside at a point near the shape
        ray.o = 4 * e.norm() * RandomUnit(rng);
        ray.d = (point_near(1.1) - ray.o) * len;
        break;
      case 3:  // from inside
        ray.o = point_near(0.3);
        ray.d = RandomUnit(rng) * len;
        break;
      case 4: {  // along the axis, from above or below (caps, tips, hemispheres)
        const double sgn = k % 20 < 10 ? 1 : -1;
        ray.o = Eigen::Vector3d((2 * rng->UniformD() - 1) * 1.2 * r,
                                (2 * rng->UniformD() - 1) * 1.2 * r, sgn * (3 * e.z() + 1));
        ray.d =
            Eigen::Vector3d(0.05 * (rng->UniformD() - 0.5), 0.05 * (rng->UniformD() - 0.5), -sgn) *
            len;
        if (k % 40 < 10) ray.d.head<2>().setZero();  // exactly parallel to the axis
        break;
      }
      case 5: {  // parallel to z = 0 (d.z == 0) at a random height
        ray.o = point_near(1.5);
        ray.o.head<2>() += Eigen::Vector2d(3 * e.x(), 0);
        ray.d = Eigen::Vector3d(-1, 0.3 * (rng->UniformD() - 0.5), 0) * len;
        break;
      }
      case 6: {  // tangent to the side (or sphere) at distance r (1 +- 1e-9)
        const double a = 2 * M_PI * rng->UniformD();
        const double rho = r * (1 + (k % 20 < 10 ? 1e-9 : -1e-9));
        const Eigen::Vector3d radial(std::cos(a), std::sin(a), 0);
        const Eigen::Vector3d along(-std::sin(a), std::cos(a), 0);
        double z = (2 * rng->UniformD() - 1) * 0.9 * h;
        if (s.kind == AnalyticKind::kSphere || s.kind == AnalyticKind::kEllipsoid) z = 0;
        if (s.kind == AnalyticKind::kPlane) z = 0.3;
        ray.o = rho * radial - 5 * along + Eigen::Vector3d(0, 0, z);
        ray.d = along * len;
        break;
      }
      case 7: {  // exactly tangent lines (discriminant exactly zero or rounding-sized)
        const double z =
            s.kind == AnalyticKind::kCylinder || s.kind == AnalyticKind::kCapsule ? 0.5 * h : 0.0;
        ray.o = Eigen::Vector3d(r, -3, z);
        ray.d = Eigen::Vector3d(0, 1, 0) * len;
        break;
      }
      case 8:  // the caps' rims and the capsule's equators: lines through z = +-h
        ray.o = Eigen::Vector3d(-3 * e.x(), (2 * rng->UniformD() - 1) * r,
                                (k % 20 < 10 ? h : -h) + 1e-9 * (rng->UniformD() - 0.5));
        ray.d = Eigen::Vector3d(1, 0, 1e-3 * (rng->UniformD() - 0.5)) * len;
        break;
      default:  // range limits
        ray.o = 4 * e.norm() * RandomUnit(rng);
        ray.d = (point_near(0.8) - ray.o) * len;
        if (k % 20 < 10) {
          ray.tmax = (rng->UniformD() * 0.6 + 0.1) / len;
        } else {
          ray.tmin = (rng->UniformD() * 0.5 + 0.5) / len;
        }
        break;
    }
    rays.push_back(ray);
  }
  return rays;
}

TEST(AnalyticLanesTest, LanesMatchTheScalarIntersectionOnManyRays) {
  // every shape, 4000 rays each, traced in batches of 1 to 16 lanes: the same hits and misses
  // as IntersectAnalytic ray by ray, the same part, and t bit for bit (or to 1e-12 with FMA).
  const AnalyticShape shapes[] = {
      Shape(AnalyticKind::kCylinder, {0.3, 0.6, 0}),
      Shape(AnalyticKind::kCylinder, {0.05, 0.02, 0}),
      Shape(AnalyticKind::kCapsule, {0.25, 0.4, 0}),
      Shape(AnalyticKind::kCapsule, {0.1, 1e-3, 0}),
      Shape(AnalyticKind::kSphere, {0.4, 0, 0}),
      Shape(AnalyticKind::kEllipsoid, {0.2, 0.5, 0.3}),
      Shape(AnalyticKind::kPlane, {1.5, 0.75, 0}),
      Shape(AnalyticKind::kPlane, {1e4, 1e4, 0}),
  };
  Rng rng(11);
  for (const AnalyticShape& s : shapes) {
    SCOPED_TRACE(static_cast<int>(s.kind));
    SCOPED_TRACE(s.size.transpose());
    const std::vector<TestRay> rays = RaysFor(s, &rng);
    int hits = 0, misses = 0, parts[3] = {0, 0, 0}, bitwise = 0;
    size_t start = 0;
    int batch = 1;
    while (start < rays.size()) {
      const int n = static_cast<int>(std::min<size_t>(batch, rays.size() - start));
      AnalyticRayLanes lanes;
      // lanes past n (computed up to AnalyticLaneWidth(n), results ignored) repeat ray 0.
      for (int i = 0; i < kAnalyticLanes; ++i) {
        const TestRay& r = rays[start + (i < n ? i : 0)];
        lanes.ox[i] = r.o.x();
        lanes.oy[i] = r.o.y();
        lanes.oz[i] = r.o.z();
        lanes.dx[i] = r.d.x();
        lanes.dy[i] = r.d.y();
        lanes.dz[i] = r.d.z();
        lanes.tmin[i] = r.tmin;
        lanes.tmax[i] = r.tmax;
      }
      AnalyticHitLanes out;
      IntersectAnalyticLanes(s, lanes, n, &out);
      for (int i = 0; i < n; ++i) {
        const TestRay& r = rays[start + i];
        double t = 0;
        ShapePart part = ShapePart::kMain;
        const bool hit = IntersectAnalytic(s, r.o, r.d, r.tmin, r.tmax, &t, &part);
        const bool lane_hit = out.t[i] < std::numeric_limits<double>::infinity();
        ASSERT_EQ(lane_hit, hit) << "ray " << start + i << " o " << r.o.transpose() << " d "
                                 << r.d.transpose();
        if (!hit) {
          ++misses;
          continue;
        }
        ++hits;
        ++parts[static_cast<int>(part)];
        EXPECT_EQ(out.part[i], static_cast<double>(static_cast<int>(part)));
        if (kBitwise) {
          EXPECT_EQ(out.t[i], t) << "ray " << start + i;
        } else {
          EXPECT_NEAR(out.t[i], t, 1e-12 * std::abs(t)) << "ray " << start + i;
        }
        bitwise += out.t[i] == t;
      }
      start += n;
      batch = batch % 16 + 1;
    }
    EXPECT_GT(hits, 1000);
    EXPECT_GT(misses, 400);
    if (s.kind == AnalyticKind::kCylinder || s.kind == AnalyticKind::kCapsule) {
      EXPECT_GT(parts[1], 50);
      EXPECT_GT(parts[2], 50);
    }
    if (kBitwise) {
      EXPECT_EQ(bitwise, hits);
    }
  }
}

TEST(AnalyticLanesTest, TransformIsEigensProduct) {
  // TransformRayLanes gives R o + p and R d of Eigen's product, bit for bit without FMA.
  Rng rng(5);
  for (int rep = 0; rep < 50; ++rep) {
    const Eigen::Matrix3d R =
        Eigen::AngleAxisd(3 * rng.UniformD(), RandomUnit(&rng)).toRotationMatrix();
    const Eigen::Vector3d p = 3 * RandomUnit(&rng);
    float ox[kAnalyticLanes], oy[kAnalyticLanes], oz[kAnalyticLanes], dx[kAnalyticLanes],
        dy[kAnalyticLanes], dz[kAnalyticLanes];
    for (int i = 0; i < kAnalyticLanes; ++i) {
      const Eigen::Vector3f o = (5 * RandomUnit(&rng)).cast<float>();
      const Eigen::Vector3f d = RandomUnit(&rng).cast<float>();
      ox[i] = o.x(), oy[i] = o.y(), oz[i] = o.z();
      dx[i] = d.x(), dy[i] = d.y(), dz[i] = d.z();
    }
    const int n = 1 + rep % 16;
    AnalyticRayLanes lanes;
    TransformRayLanes(R, p, ox, oy, oz, dx, dy, dz, n, &lanes);
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector3d o = R * Eigen::Vector3f(ox[i], oy[i], oz[i]).cast<double>() + p;
      const Eigen::Vector3d d = R * Eigen::Vector3f(dx[i], dy[i], dz[i]).cast<double>();
      const Eigen::Vector3d o_l(lanes.ox[i], lanes.oy[i], lanes.oz[i]);
      const Eigen::Vector3d d_l(lanes.dx[i], lanes.dy[i], lanes.dz[i]);
      if (kBitwise) {
        EXPECT_EQ(o_l, o);
        EXPECT_EQ(d_l, d);
      } else {
        EXPECT_LT((o_l - o).norm(), 1e-14 * (1 + o.norm()));
        EXPECT_LT((d_l - d).norm(), 1e-14);
      }
    }
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
