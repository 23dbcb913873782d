#include "penumbra/session/floor_map.h"

#include <gtest/gtest.h>

namespace penumbra {
namespace {

// a 6 x 4 m walled pen (walls 0.2 m thick, 1 m high) with a 1 m pillar in the middle and
// a low 0.03 m mat (not blocking), plus a floor plane
SceneDescription Pen() {
  SceneDescription s;
  s.bodies.push_back({"world", -1, true});
  const auto box = [&](Eigen::Vector3d c, Eigen::Vector3d half) {
    Geom g;
    g.shape = GeomShape::kBox;
    g.size = half;
    g.X_BG.translation() = c;
    s.geoms.push_back(g);
  };
  Geom floor;
  floor.shape = GeomShape::kPlane;
  floor.size = Eigen::Vector3d(10, 10, 1);
  s.geoms.push_back(floor);
  box({0, 2.1, 0.5}, {3.2, 0.1, 0.5});
  box({0, -2.1, 0.5}, {3.2, 0.1, 0.5});
  box({3.1, 0, 0.5}, {0.1, 2.2, 0.5});
  box({-3.1, 0, 0.5}, {0.1, 2.2, 0.5});
  box({0, 0, 0.5}, {0.5, 0.5, 0.5});       // pillar
  box({-2, 1, 0.015}, {0.5, 0.5, 0.015});  // mat, below the 0.05 m band
  return s;
}

TEST(FloorMap, BlocksStaticGeometryInThePeopleBandAndFloodsTheInterior) {
  const SceneDescription scene = Pen();
  FloorMap map(scene, {Pose::Identity()}, 0.0, Eigen::Vector2d(-2, -1));
  EXPECT_TRUE(map.has_static_bounds());
  EXPECT_NEAR(map.static_min_W().x(), -3.2, 1e-12);
  EXPECT_NEAR(map.static_max_W().y(), 2.2, 1e-12);
  EXPECT_TRUE(map.IsFree({-2, -1}, 0.4));
  EXPECT_TRUE(map.IsFree({-2, 1}, 0.4)) << "the mat is lower than 5 cm";
  EXPECT_FALSE(map.IsFree({0, 0}, 0.1)) << "pillar";
  EXPECT_FALSE(map.IsFree({0.8, 0}, 0.4)) << "0.3 m from the pillar";
  EXPECT_TRUE(map.IsFree({1.0, 0}, 0.4));
  EXPECT_FALSE(map.SegmentFree({-2, 0}, {2, 0}, 0.4)) << "through the pillar";
  EXPECT_TRUE(map.SegmentFree({-2, -1.2}, {2, -1.2}, 0.4));
  map.Flood({-2, -1}, 0.4);
  Eigen::Vector2d lo, hi;
  ASSERT_TRUE(map.ReachableBounds(&lo, &hi));
  // interior x in [-3, 3], y in [-2, 2], minus 0.4 m clearance (cell-rounded)
  EXPECT_NEAR(lo.x(), -2.6, 0.11);
  EXPECT_NEAR(hi.x(), 2.6, 0.11);
  EXPECT_NEAR(lo.y(), -1.6, 0.11);
  EXPECT_NEAR(hi.y(), 1.6, 0.11);
  for (uint64_t u = 0; u < 500; ++u) {
    Eigen::Vector2d p;
    ASSERT_TRUE(map.RandomFreePoint(u * 7919, &p));
    EXPECT_TRUE(map.IsFree(p, 0.4)) << p.transpose();
    EXPECT_LT(p.cwiseAbs().maxCoeff(), 3.0) << "outside the pen: " << p.transpose();
  }
}

}  // namespace
}  // namespace penumbra
