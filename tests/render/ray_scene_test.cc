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

TEST(RaySceneTest, FinitePlaneIsTheExactRectangleFromBothSides) {
  // a finite plane on a tilted, shifted pose: every ray hits it exactly
  // where the rectangle |x_G| <= 1.5, |y_G| <= 0.75, z_G = 0 is, at the analytic distance, with
  // the geom-frame point and normal of the analytic plane; seen from below it is a back face.
  SceneDescription scene = EmptyScene();
  Pose X_WG = Translation(3, 0.2, -0.1);
  X_WG.linear() = (Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()) *
                   Eigen::AngleAxisd(-1.1, Eigen::Vector3d::UnitY()))
                      .toRotationMatrix();
  AddGeom(&scene, GeomShape::kPlane, {1.5, 0.75, 0.1}, X_WG);
  RayScene rs(scene);
  rs.Update(testing::IdentitySnapshot(scene));
  const Eigen::Vector3d n_W = X_WG.linear().col(2);
  int hits = 0, misses = 0;
  for (const Eigen::Vector3d& o : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(6, -0.5, 0.3)}) {
    for (int i = -40; i <= 40; ++i)
      for (int j = -40; j <= 40; ++j) {
        const Eigen::Vector3d target =
            X_WG * Eigen::Vector3d(2.0 * i / 40 + 0.0123, 1.0 * j / 40 + 0.0071, 0);
        Ray ray;
        ray.o = o.cast<float>();
        ray.d = (target - o).normalized().cast<float>();
        const Eigen::Vector3d d = ray.d.cast<double>();
        // analytic: distance to z_G = 0 along the (float) ray, and the point there.
        const Eigen::Vector3d o_G = X_WG.inverse() * ray.o.cast<double>();
        const Eigen::Vector3d d_G = X_WG.linear().transpose() * d;
        const double t = -o_G.z() / d_G.z();
        const Eigen::Vector3d p_G = o_G + t * d_G;
        const bool inside = std::abs(p_G.x()) <= 1.5 && std::abs(p_G.y()) <= 0.75;
        // rays grazing the rectangle's border may go either way.
        const bool border =
            std::abs(std::abs(p_G.x()) - 1.5) < 1e-5 || std::abs(std::abs(p_G.y()) - 0.75) < 1e-5;
        SurfaceHit hit;
        const bool got = rs.Intersect(ray, &hit);
        if (border) continue;
        ASSERT_EQ(got, inside) << "i " << i << " j " << j << " o " << o.transpose();
        if (!got) {
          ++misses;
          continue;
        }
        ++hits;
        EXPECT_NEAR(hit.t, t, 1e-5 * t);
        EXPECT_LT((hit.p_G.cast<double>() - p_G).norm(), 1e-5);
        EXPECT_LT((hit.n_G.cast<double>() - Eigen::Vector3d::UnitZ()).norm(), 1e-6);
        const bool from_front = d.dot(n_W) < 0;
        EXPECT_EQ(hit.front_face, from_front);
        EXPECT_LT((hit.ng_W.cast<double>() - (from_front ? n_W : -n_W)).norm(), 1e-5);
        EXPECT_LT((hit.ns_W - hit.ng_W).norm(), 1e-6);
      }
  }
  EXPECT_GT(hits, 2000);
  EXPECT_GT(misses, 2000);
}

TEST(RaySceneTest, MovingBodyHitsMatchTheSameGeomsPlacedStatic) {
  // the fixture's moving body (its own instanced scene, posed with X_WB) and the same geoms as
  // static geoms at X_WB X_BG (merged world-frame scene) give the same hits up to float
  // rounding of the instance transform and the world-frame vertices.
  Fixture f;
  RayScene moving(f.scene);
  moving.Update(f.snapshot);
  SceneDescription fixed = f.scene;
  for (Geom& g : fixed.geoms) {
    if (g.body == 0) continue;
    g.X_BG = f.snapshot.X_WB[g.body] * g.X_BG;
    g.body = 0;
  }
  RayScene still(fixed);
  still.Update(testing::IdentitySnapshot(fixed));
  const int w = 61, h = 47;
  const Camera camera(testing::CameraLookingAlongX(), CameraIntrinsics::FromFovy(w, h, 70.0));
  int moving_hits = 0;
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      SCOPED_TRACE(u + w * v);
      const Ray ray = camera.GenerateRay(u, v);
      SurfaceHit a, b;
      const bool got_a = moving.Intersect(ray, &a), got_b = still.Intersect(ray, &b);
      ASSERT_EQ(got_a, got_b);
      if (!got_a) continue;
      // rays grazing a silhouette may pick the other geom; they are rare.
      if (a.geom != b.geom) continue;
      if (f.scene.geoms[a.geom].body != 0) ++moving_hits;
      EXPECT_NEAR(a.t, b.t, 1e-5 * b.t);
      EXPECT_LT((a.p_W - b.p_W).norm(), 1e-5);
      EXPECT_LT((a.p_G - b.p_G).norm(), 1e-5);
      EXPECT_LT((a.n_G - b.n_G).norm(), 1e-5);
      EXPECT_LT((a.ng_W - b.ng_W).norm(), 1e-5);
      EXPECT_LT((a.ns_W - b.ns_W).norm(), 1e-5);
      EXPECT_EQ(a.front_face, b.front_face);
      EXPECT_EQ(a.material, b.material);
    }
  EXPECT_GT(moving_hits, 100);
}

// a square plate of 2 n^2 triangles, side 1 m, in the z = 0 plane of its frame, facing +z.
TriangleMesh Plate(int n) {
  TriangleMesh mesh;
  mesh.name = "plate";
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i)
      mesh.vertices.emplace_back(static_cast<float>(i) / n - 0.5f, static_cast<float>(j) / n - 0.5f,
                                 0.0f);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
      mesh.faces.emplace_back(a, b, d);
      mesh.faces.emplace_back(a, d, c);
    }
  return mesh;
}

TEST(RaySceneTest, BoxSphereAndMeshBodiesFollowTheirPoses) {
  // a body of a box and a sphere and a body holding a 3200-triangle mesh. after every Update,
  // rays find the box face, the sphere and the plate at their exact distances for the new
  // poses, with the geom-frame points and normals of the geoms.
  SceneDescription scene = EmptyScene();
  const int robot = AddBody(&scene, "robot");
  const int arm = AddBody(&scene, "arm");
  const Eigen::Vector3d half(0.2, 0.3, 0.4);
  const int box = AddGeom(&scene, GeomShape::kBox, half, Translation(0, 0, 0), robot);
  const int sphere =
      AddGeom(&scene, GeomShape::kSphere, {0.25, 0, 0}, Translation(0, 0, 1.0), robot);
  scene.meshes.push_back(Plate(40));
  const int plate = AddGeom(&scene, GeomShape::kMesh, {1, 1, 1}, Translation(0, 0, 0), arm);
  scene.geoms[plate].mesh = 0;
  RayScene rs(scene);
  EXPECT_EQ(rs.num_triangles(), 12 + 2 * 40 * 40);
  WorldSnapshot snap = testing::IdentitySnapshot(scene);
  int commits = 0;
  for (const double yaw : {0.0, 0.3, -0.5}) {
    SCOPED_TRACE(yaw);
    // robot at x = 3 turned by `yaw` about z, off to the side of the rays to the plate; the
    // plate at x = 5, facing -x, shifted in y.
    Pose X_WR = Translation(3, -1.0 + 0.2 * yaw, -0.5);
    X_WR.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    Pose X_WA = Translation(5, -yaw, 0.1);
    X_WA.linear() = Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
    snap.X_WB[robot] = X_WR;
    snap.X_WB[arm] = X_WA;
    rs.Update(snap);
    EXPECT_EQ(rs.num_top_level_commits(), ++commits);
    SurfaceHit hit;
    // box: a ray from the origin towards its centre meets the face x_B = -half.x at
    // t = ((R^T c).x - half.x) / (R^T d).x.
    const Eigen::Vector3d c = X_WR.translation();
    Ray ray;
    ray.d = c.normalized().cast<float>();
    ASSERT_TRUE(rs.Intersect(ray, &hit));
    EXPECT_EQ(hit.geom, box);
    const Eigen::Matrix3d R_BW = X_WR.linear().transpose();
    const Eigen::Vector3d d = ray.d.cast<double>();
    const double t_box = ((R_BW * c).x() - half.x()) / (R_BW * d).x();
    EXPECT_NEAR(hit.t, t_box, 1e-5);
    EXPECT_LT((hit.n_G - Eigen::Vector3f(-1, 0, 0)).norm(), 1e-6);
    EXPECT_LT((hit.ng_W.cast<double>() + X_WR.linear().col(0)).norm(), 1e-6);
    EXPECT_NEAR(hit.p_G.x(), -half.x(), 1e-5);
    EXPECT_TRUE(hit.front_face);
    // sphere (exact analytic shape): centre 1 m above the box centre, t = |c| - r.
    const Eigen::Vector3d cs = X_WR * Eigen::Vector3d(0, 0, 1.0);
    ray.d = cs.normalized().cast<float>();
    ASSERT_TRUE(rs.Intersect(ray, &hit));
    EXPECT_EQ(hit.geom, sphere);
    const Eigen::Vector3d ds = ray.d.cast<double>();
    const double b = ds.dot(cs), a = ds.squaredNorm();
    EXPECT_NEAR(hit.t, (b - std::sqrt(b * b - a * (cs.squaredNorm() - 0.0625))) / a, 1e-6);
    // plate: the plane x = 5, its normal -x in the world, +z in the geom frame.
    const Eigen::Vector3d target(5, -yaw + 0.31, 0.1 - 0.27);
    ray.d = target.normalized().cast<float>();
    ASSERT_TRUE(rs.Intersect(ray, &hit));
    EXPECT_EQ(hit.geom, plate);
    EXPECT_NEAR(hit.t, 5.0 / ray.d.cast<double>().x(), 1e-5);
    EXPECT_LT((hit.p_W.cast<double>() - target.normalized() * hit.t).norm(), 1e-5);
    EXPECT_LT((hit.ng_W - Eigen::Vector3f(-1, 0, 0)).norm(), 1e-6);
    EXPECT_LT((hit.n_G - Eigen::Vector3f(0, 0, 1)).norm(), 1e-6);
    EXPECT_LT((hit.p_G.head<2>().cast<double>() - Eigen::Vector2d(-0.27, 0.31)).norm(), 1e-5);
    // the same poses again commit nothing.
    rs.Update(snap);
    EXPECT_EQ(rs.num_top_level_commits(), commits);
  }
}

}  // namespace
}  // namespace penumbra
