// the last line of defence: RayScene never hands Embree a ray with a NaN,
// infinite or huge (> kMaxRayComponent) origin or direction. Embree 3 aborted the process on
// such rays (`Assertion 'all(valid, ray.valid())' failed`); now they are misses, counted, and
// the other rays of the same packet are traced as before.

#include <gtest/gtest.h>

#include <limits>
#include <vector>

#include "penumbra/render/embree/ray_scene.h"
#include "render/render_test_util.h"

namespace penumbra {
namespace {

using testing::AddGeom;
using testing::EmptyScene;
using testing::Translation;

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// a box 4 m ahead along +x and a sphere at the same distance (analytic user geometry).
struct Target {
  SceneDescription scene = EmptyScene();
  Target() {
    AddGeom(&scene, GeomShape::kBox, {0.5, 0.5, 0.5}, Translation(4, 0, 0));
    AddGeom(&scene, GeomShape::kSphere, {0.5, 0, 0}, Translation(4, 3, 0));
  }
};

Ray MakeRay(Eigen::Vector3f o, Eigen::Vector3f d) {
  Ray r;
  r.o = o;
  r.d = d;
  return r;
}

std::vector<Ray> BadRays() {
  return {MakeRay({1e19f, 0, 0}, {1, 0, 0}),
          MakeRay({0, 0, 0}, {1e30f, 0, 0}),
          MakeRay({kNaN, 0, 0}, {1, 0, 0}),
          MakeRay({0, 0, 0}, {1, kInf, 0}),
          MakeRay({0, 0, -kInf}, {0, 0, 1}),
          [] {
            Ray r = MakeRay({0, 0, 0}, {1, 0, 0});
            r.tmax = kNaN;
            return r;
          }()};
}

TEST(UntraceableRay, IsTraceableRayDrawsTheLineAtKMaxRayComponent) {
  EXPECT_TRUE(IsTraceableRay(MakeRay({1e18f, -1e18f, 0}, {1, 0, 0})));
  EXPECT_TRUE(IsTraceableRay(MakeRay({0, 0, 0}, {1, 0, 0})));  // tmax = +inf is fine
  for (const Ray& r : BadRays()) EXPECT_FALSE(IsTraceableRay(r));
}

TEST(UntraceableRay, SingleRaysMissAndAreCounted) {
  Target t;
  RayScene rs(t.scene);
  rs.Update(testing::IdentitySnapshot(t.scene));
  SurfaceHit hit;
  ASSERT_TRUE(rs.Intersect(MakeRay({0, 0, 0}, {1, 0, 0}), &hit));
  EXPECT_NEAR(hit.t, 3.5f, 1e-5f);
  EXPECT_EQ(rs.num_untraceable_rays(), 0);
  const std::vector<Ray> bad = BadRays();
  for (const Ray& r : bad) {
    EXPECT_FALSE(rs.Intersect(r, &hit));
    EXPECT_FALSE(rs.Occluded(r));
  }
  EXPECT_EQ(rs.num_untraceable_rays(), 2 * static_cast<int64_t>(bad.size()));
}

TEST(UntraceableRay, PacketsTraceTheGoodLanesAndMissTheBadOnes) {
  Target t;
  RayScene rs(t.scene);
  rs.Update(testing::IdentitySnapshot(t.scene));
  // 16 good rays at the box, every third one replaced by a bad ray
  std::vector<Ray> rays(16, MakeRay({0, 0, 0}, {1, 0, 0}));
  const std::vector<Ray> bad = BadRays();
  int num_bad = 0;
  for (int i = 0; i < 16; i += 3) rays[i] = bad[num_bad++ % bad.size()];
  std::vector<SurfaceHit> hits(16);
  std::unique_ptr<bool[]> did_hit(new bool[16]);
  rs.IntersectMany(rays.data(), 16, /*coherent=*/true, hits.data(), did_hit.get());
  for (int i = 0; i < 16; ++i) {
    if (i % 3 == 0) {
      EXPECT_FALSE(did_hit[i]) << i;
    } else {
      ASSERT_TRUE(did_hit[i]) << i;
      EXPECT_NEAR(hits[i].t, 3.5f, 1e-5f);
    }
  }
  // a whole packet of bad rays
  std::vector<Ray> all_bad(16, bad[0]);
  rs.IntersectMany(all_bad.data(), 16, /*coherent=*/true, hits.data(), did_hit.get());
  for (int i = 0; i < 16; ++i) EXPECT_FALSE(did_hit[i]);
  // shadow lanes (the realtime tier): lanes 0-7 good (blocked by the box), 8-15 bad
  Vec3Lanes o{Lanes::Zero(), Lanes::Zero(), Lanes::Zero()};
  Vec3Lanes d{Lanes::Ones(), Lanes::Zero(), Lanes::Zero()};
  Lanes tmax = Lanes::Constant(10);
  for (int k = 8; k < 16; ++k) o.x[k] = k % 2 ? kNaN : 1e30f;
  LaneMask occluded;
  rs.OccludedLanes(o, d, tmax, LaneMask::Constant(true), &occluded);
  for (int k = 0; k < 16; ++k) EXPECT_EQ(occluded[k], k < 8) << k;
  EXPECT_EQ(rs.num_untraceable_rays(), num_bad + 16 + 8);
}

}  // namespace
}  // namespace penumbra
