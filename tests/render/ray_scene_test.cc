// RayScene's batched tracing: IntersectGrid (4 x 4 packets) and IntersectMany give exactly the
// hits of tracing every ray alone.

#include "penumbra/render/ray_scene.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "penumbra/render/camera.h"
#include "render_test_util.h"

namespace penumbra {
namespace {

using testing::AddBody;
using testing::AddGeom;
using testing::EmptyScene;
using testing::Translation;

// every shape, static and on a moving body (posed away from the identity), in front of a
// camera at the origin looking along +x.
struct Fixture {
  SceneDescription scene = EmptyScene();
  WorldSnapshot snapshot;
  Fixture() {
    AddGeom(&scene, GeomShape::kPlane, {0, 0, 1}, Translation(0, 0, -1));
    AddGeom(&scene, GeomShape::kBox, {0.3, 0.4, 0.5}, Translation(4, 0.8, 0.2));
    AddGeom(&scene, GeomShape::kSphere, {0.35, 0, 0}, Translation(3, -0.7, 0.1));
    const int body = AddBody(&scene, "mover");
    Pose X_BG = Translation(0, 0.3, 0);
    X_BG.linear() =
        Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    AddGeom(&scene, GeomShape::kCapsule, {0.15, 0.3, 0}, X_BG, body);
    AddGeom(&scene, GeomShape::kCylinder, {0.2, 0.25, 0}, Translation(0, -0.4, 0.2), body);
    AddGeom(&scene, GeomShape::kEllipsoid, {0.2, 0.3, 0.15}, Translation(0, 0.1, -0.45), body);
    AddGeom(&scene, GeomShape::kBox, {0.1, 0.1, 0.1}, Translation(0.1, -0.1, 0.5), body);
    snapshot = testing::IdentitySnapshot(scene);
    snapshot.X_WB[body] = Translation(2.5, 0.1, -0.1);
    snapshot.X_WB[body].linear() =
        Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  }
};

void ExpectSameHit(const SurfaceHit& a, const SurfaceHit& b) {
  EXPECT_EQ(a.t, b.t);
  EXPECT_EQ(a.geom, b.geom);
  EXPECT_EQ(a.material, b.material);
  EXPECT_EQ(a.p_W, b.p_W);
  EXPECT_EQ(a.ng_W, b.ng_W);
  EXPECT_EQ(a.ns_W, b.ns_W);
  EXPECT_EQ(a.p_G, b.p_G);
  EXPECT_EQ(a.n_G, b.n_G);
  EXPECT_EQ(a.front_face, b.front_face);
  EXPECT_EQ(a.has_uv, b.has_uv);
}

TEST(RaySceneTest, GridAndManyMatchSingleRays) {
  Fixture f;
  RayScene rs(f.scene);
  rs.Update(f.snapshot);
  // a grid whose sides are not multiples of 4 (partial packets at the right and bottom).
  const int w = 37, h = 23;
  const Camera camera(testing::CameraLookingAlongX(), CameraIntrinsics::FromFovy(w, h, 70.0));
  std::vector<Ray> rays;
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) rays.push_back(camera.GenerateRay(u, v));
  const int n = w * h;
  std::vector<SurfaceHit> single(n), grid(n), many(n);
  std::unique_ptr<bool[]> hit_single(new bool[n]), hit_grid(new bool[n]), hit_many(new bool[n]);
  for (int i = 0; i < n; ++i) hit_single[i] = rs.Intersect(rays[i], &single[i]);
  rs.IntersectGrid(rays.data(), w, h, grid.data(), hit_grid.get());
  rs.IntersectMany(rays.data(), n, /*coherent=*/true, many.data(), hit_many.get());
  int hits = 0;
  std::vector<bool> geom_seen(f.scene.geoms.size(), false);
  for (int i = 0; i < n; ++i) {
    SCOPED_TRACE(i);
    ASSERT_EQ(hit_grid[i], hit_single[i]);
    ASSERT_EQ(hit_many[i], hit_single[i]);
    if (!hit_single[i]) continue;
    ++hits;
    geom_seen[single[i].geom] = true;
    ExpectSameHit(grid[i], single[i]);
    ExpectSameHit(many[i], single[i]);
  }
  // the test sees most of the scene: misses and hits, and every geom.
  EXPECT_GT(hits, n / 4);
  EXPECT_LT(hits, n);
  for (size_t g = 0; g < geom_seen.size(); ++g) EXPECT_TRUE(geom_seen[g]) << "geom " << g;
}

TEST(RaySceneTest, AnalyticHitsFollowTheBodyPose) {
  // a sphere on a moving body: after Update, the hit point and normal follow the new pose
  // (FinishHit folds the instance pose into each analytic geom).
  SceneDescription scene = EmptyScene();
  const int body = AddBody(&scene, "ball");
  AddGeom(&scene, GeomShape::kSphere, {0.5, 0, 0}, Translation(0, 0, 0), body);
  RayScene rs(scene);
  WorldSnapshot snap = testing::IdentitySnapshot(scene);
  for (double y : {0.0, 0.25, -0.3}) {
    snap.X_WB[body] = Translation(3, y, 0);
    rs.Update(snap);
    Ray ray;
    ray.o = Eigen::Vector3f(0, 0, 0);
    ray.d = Eigen::Vector3f(1, 0, 0);
    SurfaceHit hit;
    ASSERT_TRUE(rs.Intersect(ray, &hit));
    const double expected_t = 3.0 - std::sqrt(0.25 - y * y);
    EXPECT_NEAR(hit.t, expected_t, 1e-6);
    const Eigen::Vector3d n_expected =
        (Eigen::Vector3d(expected_t, 0, 0) - Eigen::Vector3d(3, y, 0)).normalized();
    EXPECT_LT((hit.ng_W.cast<double>() - n_expected).norm(), 1e-5);
    EXPECT_LT((hit.p_G.cast<double>() - Eigen::Vector3d(expected_t - 3, -y, 0)).norm(), 1e-5);
  }
}

}  // namespace
}  // namespace penumbra
