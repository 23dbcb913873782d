// MovingBounds: the cone and segment tests never clear rays that hit a moving geom's box, and
// do clear rays that pass the boxes (the static-only path of RayScene depends on both).

#include "penumbra/render/geometry/moving_bounds.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "penumbra/render/camera/camera.h"
#include "penumbra/render/geometry/ray_cone.h"

namespace penumbra {
namespace {

using Box = MovingBounds::Box;

// whether the segment o + t d, t in [tmin, tmax], meets box b (exact slab test in double, in
// the box's coordinates x with p = c + axes x, |x|_inf <= 1).
bool SegmentHitsBox(const Box& b, const Eigen::Vector3f& o, const Eigen::Vector3f& d, double tmin,
                    double tmax) {
  const Eigen::Matrix3d A = b.axes.cast<double>();
  const Eigen::Vector3d x0 = A.inverse() * (o.cast<double>() - b.c.cast<double>());
  const Eigen::Vector3d dx = A.inverse() * d.cast<double>();
  double lo = tmin, hi = tmax;
  for (int k = 0; k < 3; ++k) {
    if (dx[k] == 0) {
      if (std::abs(x0[k]) > 1) return false;
      continue;
    }
    double t0 = (-1 - x0[k]) / dx[k], t1 = (1 - x0[k]) / dx[k];
    if (t0 > t1) std::swap(t0, t1);
    lo = std::max(lo, t0), hi = std::min(hi, t1);
  }
  return lo <= hi;
}

Box RandomBox(std::mt19937* rng, const Eigen::Vector3f& c, float size) {
  std::uniform_real_distribution<float> u(-1, 1);
  const Eigen::Matrix3f R =
      Eigen::AngleAxisf(3 * u(*rng), Eigen::Vector3f(u(*rng), u(*rng), u(*rng)).normalized())
          .toRotationMatrix();
  Box b;
  b.c = c;
  const Eigen::Vector3f h(size * (0.2f + std::abs(u(*rng))), size * (0.2f + std::abs(u(*rng))),
                          size * (0.2f + std::abs(u(*rng))));
  b.axes = R * h.asDiagonal();
  return b;
}

Pose RandomPose(std::mt19937* rng, float reach) {
  std::uniform_real_distribution<double> u(-1, 1);
  Pose X = Pose::Identity();
  X.linear() =
      Eigen::AngleAxisd(3 * u(*rng), Eigen::Vector3d(u(*rng), u(*rng), u(*rng)).normalized())
          .toRotationMatrix();
  X.translation() = reach * Eigen::Vector3d(u(*rng), u(*rng), u(*rng));
  return X;
}

// world-frame copy of a body-frame box.
Box Posed(const Box& b, const Pose& X) {
  const Eigen::Matrix3f R = X.linear().cast<float>();
  return {R * b.c + X.translation().cast<float>(), R * b.axes};
}

TEST(MovingBoundsTest, SegmentsThatHitABoxAreNeverCleared) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-1, 1);
  int hit = 0, cleared = 0, trials = 0;
  for (int scene = 0; scene < 20; ++scene) {
    MovingBounds mb;
    std::vector<Box> world_boxes;
    for (int body = 0; body < 6; ++body) {
      std::vector<Box> boxes;
      for (int i = 0; i < 1 + body % 3; ++i)
        boxes.push_back(RandomBox(&rng, 0.3f * Eigen::Vector3f(u(rng), u(rng), u(rng)), 0.15f));
      mb.AddBody(boxes, body / 3);  // two clusters of three bodies
      const Pose X = RandomPose(&rng, 3);
      mb.SetPose(body, X);
      for (const Box& b : boxes) world_boxes.push_back(Posed(b, X));
    }
    mb.AddBody({}, 7);  // a body without geoms is never hit
    mb.CommitPoses();
    for (int batch = 0; batch < 40; ++batch) {
      Vec3Lanes o, d;
      Lanes tmax;
      for (int k = 0; k < kLanes; ++k) {
        const float r = u(rng);
        tmax[k] = r < -0.5f ? std::numeric_limits<float>::infinity() : 1.5f * (r + 1);
        if (k % 2 == 1) {
          // anywhere, in any direction.
          o.Set(k, 6 * Eigen::Vector3f(u(rng), u(rng), u(rng)));
          d.Set(k, Eigen::Vector3f(u(rng), u(rng), u(rng)));
          continue;
        }
        // aimed at a point near a random box (some cut short, some endless).
        const Box& target = world_boxes[rng() % world_boxes.size()];
        const Eigen::Vector3f aim =
            target.c + target.axes * Eigen::Vector3f(1.3f * u(rng), 1.3f * u(rng), 1.3f * u(rng));
        const Eigen::Vector3f start = aim + 4 * Eigen::Vector3f(u(rng), u(rng), u(rng));
        const Eigen::Vector3f dir = (aim - start) * (0.5f + std::abs(u(rng)));
        o.Set(k, start);
        d.Set(k, dir);
      }
      const LaneMask active(static_cast<uint32_t>(rng()) | 1u);
      const LaneMask may = mb.SegmentsMayHit(o, d, tmax, active);
      for (int k = 0; k < kLanes; ++k) {
        if (!active[k]) {
          EXPECT_FALSE(may[k]);
          continue;
        }
        ++trials;
        bool exact = false;
        for (const Box& b : world_boxes)
          exact = exact || SegmentHitsBox(b, o.Lane(k), d.Lane(k), 0, tmax[k]);
        if (exact) {
          ++hit;
          EXPECT_TRUE(may[k]) << "scene " << scene << " batch " << batch << " lane " << k;
        }
        if (!may[k]) ++cleared;
      }
    }
  }
  // both outcomes occur often: the test exercises hits and clears.
  EXPECT_GT(hit, trials / 10);
  EXPECT_GT(cleared, trials / 10);
}

// the rays of pixel tile (x0, y0) of `camera`, 16 x 16 pixels.
std::vector<Ray> TileRays(const Camera& camera, int x0, int y0, float tmin) {
  std::vector<Ray> rays;
  for (int y = y0; y < y0 + 16; ++y)
    for (int x = x0; x < x0 + 16; ++x) {
      rays.push_back(camera.GenerateRay(x, y));
      rays.back().tmin = tmin;
    }
  return rays;
}

TEST(MovingBoundsTest, ConesThatHitABoxAreNeverCleared) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> u(-1, 1);
  int hit = 0, cleared = 0, trials = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const Pose X_WO = RandomPose(&rng, 2);
    const Camera camera(X_WO, CameraIntrinsics::FromFovy(320, 240, 80));
    const int x0 = 16 * static_cast<int>(rng() % 20), y0 = 16 * static_cast<int>(rng() % 15);
    const std::vector<Ray> rays = TileRays(camera, x0, y0, 0.02f);
    // a small box near a ray of the tile or of a pixel just outside it, at 0.05 .. 3 m.
    const Ray aim = camera.GenerateRay(x0 - 3 + static_cast<int>(rng() % 22),
                                       y0 - 3 + static_cast<int>(rng() % 22));
    const float depth = 0.05f + 3 * std::abs(u(rng));
    const float size = 0.002f + 0.05f * depth * std::abs(u(rng));
    MovingBounds mb;
    const Box box = RandomBox(&rng, aim.o + depth * aim.d, size);
    mb.AddBody({box}, 0);
    mb.CommitPoses();
    bool exact = false;
    for (const Ray& r : rays) exact = exact || SegmentHitsBox(box, r.o, r.d, r.tmin, 1e9);
    const RayCone corners =
        RayCone::FromCorners(rays[0].o, {rays[0].d, rays[15].d, rays[255].d, rays[240].d}, 0.02f);
    const bool may_corners = mb.MayHit(corners);
    const bool may_rays = mb.MayHit(RayCone::FromRays(rays.data(), 256));
    ++trials;
    if (exact) {
      ++hit;
      EXPECT_TRUE(may_corners) << "trial " << trial;
      EXPECT_TRUE(may_rays) << "trial " << trial;
    }
    if (!may_corners) ++cleared;
  }
  EXPECT_GT(hit, trials / 10);
  EXPECT_GT(cleared, trials / 10);
}

TEST(MovingBoundsTest, CameraHousingRightBehindTheCameraIsClearedForEveryTile) {
  // a 10 x 9 x 3 cm housing whose front face is 0.5 mm behind the optical centre; the camera
  // (90 deg vertical field of view) looks straight out of it, or turned 30 deg to the side.
  for (double yaw_deg : {0.0, 30.0}) {
    SCOPED_TRACE(yaw_deg);
    Box housing;
    housing.c = {-0.0505f, 0, 0};
    housing.axes = Eigen::Vector3f(0.05f, 0.045f, 0.015f).asDiagonal();
    MovingBounds mb;
    mb.AddBody({housing}, 0);
    Pose X_WB = Pose::Identity();
    X_WB.translation() = Eigen::Vector3d(1, 2, 0.3);
    X_WB.linear() = Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    mb.SetPose(0, X_WB);
    mb.CommitPoses();
    // optical frame: z along the body's x (turned by yaw), x along the body's -y, y along -z.
    Eigen::Matrix3d R_BO;
    R_BO.col(0) = -Eigen::Vector3d::UnitY();
    R_BO.col(1) = -Eigen::Vector3d::UnitZ();
    R_BO.col(2) = Eigen::Vector3d::UnitX();
    Pose X_BO = Pose::Identity();
    X_BO.linear() =
        Eigen::AngleAxisd(yaw_deg * M_PI / 180, Eigen::Vector3d::UnitZ()).toRotationMatrix() * R_BO;
    const Camera camera(X_WB * X_BO, CameraIntrinsics::FromFovy(160, 128, 90));
    for (int y0 = 0; y0 < 128; y0 += 16)
      for (int x0 = 0; x0 < 160; x0 += 16) {
        const std::vector<Ray> rays = TileRays(camera, x0, y0, 0.0f);
        EXPECT_FALSE(mb.MayHit(
            RayCone::FromCorners(rays[0].o, {rays[0].d, rays[15].d, rays[255].d, rays[240].d}, 0)))
            << "tile " << x0 << " " << y0;
      }
    // the same housing 2 mm further forward reaches in front of the optical centre.
    housing.c.x() += 0.002f;
    MovingBounds ahead;
    ahead.AddBody({housing}, 0);
    ahead.SetPose(0, X_WB);
    ahead.CommitPoses();
    const std::vector<Ray> rays = TileRays(camera, 0, 0, 0.0f);
    EXPECT_TRUE(ahead.MayHit(
        RayCone::FromCorners(rays[0].o, {rays[0].d, rays[15].d, rays[255].d, rays[240].d}, 0)));
  }
}

TEST(MovingBoundsTest, NoBodiesNeverHitAndInvalidConesMay) {
  MovingBounds none;
  EXPECT_FALSE(none.MayHit(RayCone{}));
  Vec3Lanes o{Lanes::Zero(), Lanes::Zero(), Lanes::Zero()};
  Vec3Lanes d{Lanes::Ones(), Lanes::Zero(), Lanes::Zero()};
  EXPECT_FALSE(none.SegmentsMayHit(o, d, Lanes::Ones(), LaneMask::Constant(true)).any());
  MovingBounds one;
  Box b;
  b.c = {5, 0, 0};
  b.axes = Eigen::Matrix3f::Identity();
  one.AddBody({b}, 0);
  one.CommitPoses();
  EXPECT_TRUE(one.MayHit(RayCone{}));  // no bound on the rays
  // segments along +x from the origin: of length 3 they stop short of the box, of 4.5 not.
  EXPECT_FALSE(one.SegmentsMayHit(o, d, Lanes::Constant(3.0f), LaneMask::Constant(true)).any());
  EXPECT_TRUE(one.SegmentsMayHit(o, d, Lanes::Constant(4.5f), LaneMask::Constant(true)).all());
}

}  // namespace
}  // namespace penumbra
