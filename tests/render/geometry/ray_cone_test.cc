// RayCone: the cones built from rays and from a pinhole tile's corner rays hold every ray.

#include "penumbra/render/geometry/ray_cone.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <vector>

#include "penumbra/render/camera/camera.h"

namespace penumbra {
namespace {

// a camera at `o` looking along `forward` (up roughly +z), w x h pixels, vertical fov fovy_deg.
Camera MakeCamera(const Eigen::Vector3d& o, const Eigen::Vector3d& forward, int w, int h,
                  double fovy_deg, const CameraMotion& motion = {}) {
  const Eigen::Vector3d z = forward.normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Pose X_WO = Pose::Identity();
  X_WO.linear().col(0) = x;
  X_WO.linear().col(1) = y;
  X_WO.linear().col(2) = z;
  X_WO.translation() = o;
  return Camera(X_WO, CameraIntrinsics::FromFovy(w, h, fovy_deg), motion);
}

// every point o + t d, t in [tmin, tmin + 50 |d|^-1], of every ray lies inside every plane of
// `cone` (up to 1e-6 |p - apex|; points and distances in double) and within its angle of the
// axis.
void ExpectHoldsRays(const RayCone& cone, const std::vector<Ray>& rays) {
  ASSERT_TRUE(cone.valid);
  for (const Ray& r : rays) {
    const Eigen::Vector3d o = r.o.cast<double>(), d = r.d.cast<double>();
    for (double s : {0.0, 0.01, 1.0, 50.0}) {
      const Eigen::Vector3d p = o + (r.tmin + s / d.norm()) * d;
      const Eigen::Vector3d v = p - cone.apex.cast<double>();
      for (const RayCone::Plane& pl : cone.planes)
        EXPECT_GE(pl.n.cast<double>().dot(v) - pl.offset, -cone.delta - 1e-6 * v.norm())
            << pl.n.transpose();
    }
    const double sin_angle = d.normalized().cross(cone.axis.cast<double>()).norm();
    EXPECT_LE(sin_angle, cone.sin_theta);
    EXPECT_GT(d.dot(cone.axis.cast<double>()), 0);
  }
}

TEST(RayConeTest, PinholeTileCornersHoldEveryRayOfTheTile) {
  const Camera camera = MakeCamera({1, -2, 0.4}, {0.3, 1, -0.2}, 640, 480, 75);
  ASSERT_TRUE(camera.projective());
  for (int y0 : {0, 224, 464})
    for (int x0 : {0, 304, 624}) {
      SCOPED_TRACE(::testing::Message() << "tile " << x0 << " " << y0);
      std::vector<Ray> rays;
      for (int y = y0; y < y0 + 16; ++y)
        for (int x = x0; x < x0 + 16; ++x) {
          rays.push_back(camera.GenerateRay(x, y));
          rays.back().tmin = 0.05f;
        }
      const RayCone cone =
          RayCone::FromCorners(rays[0].o, {rays[0].d, rays[15].d, rays[255].d, rays[240].d}, 0.05f);
      ExpectHoldsRays(cone, rays);
      ExpectHoldsRays(RayCone::FromRays(rays.data(), static_cast<int>(rays.size())), rays);
      // the near plane is the closest tmin point along the axis.
      EXPECT_GT(cone.planes[4].offset, 0.04f);
    }
}

TEST(RayConeTest, ConeOfRaysWithSpreadOriginsHoldsThemWithDelta) {
  // a rolling-shutter camera that moves 5 cm and turns 3 deg during the readout.
  CameraMotion motion;
  motion.end_sec = 0.03;
  motion.line_time_sec = 0.03 / 480;
  motion.X_WO_end = MakeCamera({1.05, -2, 0.4}, {0.35, 1, -0.2}, 8, 8, 60).X_WO();
  const Camera camera = MakeCamera({1, -2, 0.4}, {0.3, 1, -0.2}, 640, 480, 75, motion);
  ASSERT_FALSE(camera.projective());
  std::vector<Ray> rays;
  for (int y = 100; y < 132; ++y)
    for (int x = 200; x < 232; ++x) rays.push_back(camera.GenerateRay(x, y));
  const RayCone cone = RayCone::FromRays(rays.data(), static_cast<int>(rays.size()));
  ExpectHoldsRays(cone, rays);
  EXPECT_GT(cone.delta, 0);
  EXPECT_LT(cone.delta, 0.01f);
}

TEST(RayConeTest, RaysWiderThanAHalfSpaceOrBehindTheirStartGiveNoCone) {
  std::vector<Ray> rays(3);
  rays[0].d = {1, 0, 0};
  rays[1].d = {0, 1, 0};
  rays[2].d = {-1, 0.01f, 0};
  EXPECT_FALSE(RayCone::FromRays(rays.data(), 3).valid);
  EXPECT_FALSE(
      RayCone::FromCorners({0, 0, 0}, {rays[0].d, rays[1].d, rays[2].d, rays[0].d}, 0).valid);
  rays.assign(2, Ray{});
  rays[1].tmin = -1;  // starts behind its origin
  EXPECT_FALSE(RayCone::FromRays(rays.data(), 2).valid);
  EXPECT_FALSE(RayCone::FromRays(rays.data(), 0).valid);
}

TEST(RayConeTest, RandomRayBundlesAreHeld) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-1, 1);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Vector3f axis = Eigen::Vector3f(u(rng), u(rng), u(rng)).normalized();
    const float spread = 0.05f + 0.9f * (u(rng) + 1) / 2;
    const Eigen::Vector3f o(10 * u(rng), 10 * u(rng), 10 * u(rng));
    std::vector<Ray> rays(40);
    for (Ray& r : rays) {
      r.o = o + 0.01f * Eigen::Vector3f(u(rng), u(rng), u(rng));
      r.d = (axis + spread * Eigen::Vector3f(u(rng), u(rng), u(rng))) * (1 + u(rng) * 0.5f);
      r.tmin = 0.1f * (u(rng) + 1);
    }
    const RayCone cone = RayCone::FromRays(rays.data(), static_cast<int>(rays.size()));
    if (!cone.valid) continue;  // a bundle too wide
    ExpectHoldsRays(cone, rays);
  }
}

}  // namespace
}  // namespace penumbra
