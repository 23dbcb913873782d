// RayScene's batched tracing: IntersectGrid (4 x 4 packets) and IntersectMany give exactly the
// hits of tracing every ray alone.

#include "penumbra/render/embree/ray_scene.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <random>
#include <span>
#include <vector>

#include "penumbra/core/error.h"
#include "penumbra/render/camera/camera.h"
#include "penumbra/render/geometry/analytic_shapes.h"
#include "penumbra/render/geometry/ray_cone.h"
#include "render/render_test_util.h"

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

TEST(RaySceneTest, GridManyAndRayQueryBatchesMatchSingleRays) {
  Fixture f;
  RayScene rs(f.scene);
  const RayQuery& query = rs;  // the backend-neutral batch interface (LiDAR, sky volume)
  rs.Update(f.snapshot);
  // a grid whose sides are not multiples of 4 (partial packets at the right and bottom).
  const int w = 37, h = 23;
  const Camera camera(testing::CameraLookingAlongX(), CameraIntrinsics::FromFovy(w, h, 70.0));
  std::vector<Ray> rays;
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) rays.push_back(camera.GenerateRay(u, v));
  const int n = w * h;
  std::vector<SurfaceHit> single(n), grid(n), many(n), batch(n);
  std::unique_ptr<bool[]> hit_single(new bool[n]), hit_grid(new bool[n]), hit_many(new bool[n]),
      hit_batch(new bool[n]);
  for (int i = 0; i < n; ++i) hit_single[i] = rs.Intersect(rays[i], &single[i]);
  rs.IntersectGrid(rays.data(), w, h, grid.data(), hit_grid.get());
  rs.IntersectMany(rays.data(), n, /*coherent=*/true, many.data(), hit_many.get());
  query.Intersect(rays, batch, {hit_batch.get(), static_cast<size_t>(n)});
  int hits = 0;
  std::vector<bool> geom_seen(f.scene.geoms.size(), false);
  for (int i = 0; i < n; ++i) {
    SCOPED_TRACE(i);
    ASSERT_EQ(hit_grid[i], hit_single[i]);
    ASSERT_EQ(hit_many[i], hit_single[i]);
    ASSERT_EQ(hit_batch[i], hit_single[i]);
    if (!hit_single[i]) continue;
    ++hits;
    geom_seen[single[i].geom] = true;
    ExpectSameHit(grid[i], single[i]);
    ExpectSameHit(many[i], single[i]);
    ExpectSameHit(batch[i], single[i]);
  }
  // the test sees most of the scene: misses and hits, and every geom.
  EXPECT_GT(hits, n / 4);
  EXPECT_LT(hits, n);
  for (size_t g = 0; g < geom_seen.size(); ++g) EXPECT_TRUE(geom_seen[g]) << "geom " << g;
}

TEST(RaySceneTest, RayQueryBatchNeedsRoomForEveryHit) {
  Fixture f;
  RayScene rs(f.scene);
  const RayQuery& query = rs;
  std::vector<Ray> rays(5);
  std::vector<SurfaceHit> hits(5);
  bool did_hit[5];
  EXPECT_THROW(query.Intersect(rays, std::span(hits).first(4), did_hit), Error);
  EXPECT_THROW(query.Intersect(rays, hits, std::span(did_hit).first(4)), Error);
  EXPECT_NO_THROW(query.Intersect(rays, hits, did_hit));
  EXPECT_NO_THROW(query.Intersect({}, {}, {}));
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

// ---- analytic planes through RayScene: exact depths, edges, grazing angles, shadows ----

// the analytic reference of a plane of half-size (sx, sy) posed at X_WG: IntersectAnalytic on
// the float ray taken to the geom frame in double. returns false on a miss.
bool ReferencePlaneHit(const Pose& X_WG, double sx, double sy, const Ray& ray, double* t,
                       Eigen::Vector3d* p_G) {
  AnalyticShape plane;
  plane.kind = AnalyticKind::kPlane;
  plane.size = {sx, sy, 0};
  const Eigen::Matrix3d R_GW = X_WG.linear().transpose();
  const Eigen::Vector3d o_G = R_GW * (ray.o.cast<double>() - X_WG.translation());
  const Eigen::Vector3d d_G = R_GW * ray.d.cast<double>();
  ShapePart part;
  if (!IntersectAnalytic(plane, o_G, d_G, ray.tmin, ray.tmax, t, &part)) return false;
  *p_G = o_G + *t * d_G;
  return true;
}

// the hit matches the analytic plane: t to float rounding (1 ulp), the geom-frame point to
// float rounding of the distance, the normals exactly +-n_W.
void ExpectPlaneHit(const SurfaceHit& hit, const Ray& ray, const Pose& X_WG, double t,
                    const Eigen::Vector3d& p_G) {
  EXPECT_NEAR(hit.t, t, 1.2e-7 * t);
  const double scale = t * ray.d.cast<double>().norm() + p_G.norm();
  EXPECT_LT((hit.p_G.cast<double>() - p_G).norm(), 3e-7 * scale + 1e-9);
  EXPECT_EQ(hit.n_G, Eigen::Vector3f(0, 0, 1));
  const Eigen::Vector3d n_W = X_WG.linear().col(2);
  const bool from_front = ray.d.cast<double>().dot(n_W) < 0;
  EXPECT_EQ(hit.front_face, from_front);
  EXPECT_LT((hit.ng_W.cast<double>() - (from_front ? n_W : -n_W)).norm(), 1e-7);
  EXPECT_EQ(hit.ns_W, hit.ng_W);
}

Ray RayTo(const Eigen::Vector3d& o, const Eigen::Vector3d& target) {
  Ray r;
  r.o = o.cast<float>();
  r.d = (target - o).cast<float>();
  return r;
}

TEST(RaySceneTest, AxisAlignedFloorsMatchTheAnalyticPlaneAndAreWatertight) {
  // the default world's floors: a finite 4 x 3 m floor at z = 0 and an infinite one (half-size
  // kInfinitePlaneHalfSize) 2 cm below, seen from a low camera; every hit is the analytic one,
  // rays aimed at the diagonals (where a two-triangle plane would crack) all hit, and rays 1e-5 m
  // past the finite floor's edges go through to the infinite one.
  SceneDescription scene = EmptyScene();
  const Pose X_floor = Translation(0, 0, 0), X_ground = Translation(0, 0, -0.02);
  const int floor = AddGeom(&scene, GeomShape::kPlane, {4, 3, 0.1}, X_floor);
  const int ground = AddGeom(&scene, GeomShape::kPlane, {0, 0, 1}, X_ground);
  RayScene rs(scene);
  rs.Update(testing::IdentitySnapshot(scene));
  EXPECT_EQ(rs.num_triangles(), 0);
  int checked = 0;
  for (const Eigen::Vector3d& o :
       {Eigen::Vector3d(0.4, -0.3, 0.355), Eigen::Vector3d(-3.1, 2.2, 1.7),
        Eigen::Vector3d(2.0, 0.5, -0.5)}) {
    for (int i = 0; i <= 200; ++i) {
      const double s = -1 + 2.0 * i / 200;
      for (const double off : {0.0, 1e-7, -1e-7, 1e-6, -1e-6, 3e-4}) {
        // points on the diagonals y = +-3/4 x, moved by `off` normal to them.
        for (const double sign : {1.0, -1.0}) {
          const Eigen::Vector2d n = Eigen::Vector2d(-3 * sign, 4).normalized();
          const Eigen::Vector2d q = Eigen::Vector2d(4 * s, 3 * s * sign) * 0.999 + off * n;
          const Ray ray = RayTo(o, Eigen::Vector3d(q.x(), q.y(), 0));
          double t;
          Eigen::Vector3d p_G;
          const bool from_below = o.z() < 0;
          SurfaceHit hit;
          ASSERT_TRUE(rs.Intersect(ray, &hit)) << o.transpose() << " s " << s << " off " << off;
          // from below, the ground (2 cm below the floor) comes first.
          const int expected = from_below ? ground : floor;
          ASSERT_EQ(hit.geom, expected);
          const Pose& X = from_below ? X_ground : X_floor;
          const double half = from_below ? kInfinitePlaneHalfSize : 4.0;
          ASSERT_TRUE(ReferencePlaneHit(X, half, from_below ? half : 3.0, ray, &t, &p_G));
          ExpectPlaneHit(hit, ray, X, t, p_G);
          EXPECT_FALSE(rs.Occluded(SpawnRay(hit, -ray.d)));
          ++checked;
        }
      }
      // just inside / just outside the edges x = +-4 and y = +-3 (from above).
      if (o.z() < 0) continue;
      for (const double eps : {1e-5, -1e-5}) {
        for (const Eigen::Vector3d& q :
             {Eigen::Vector3d(4 + eps, 2.9 * s, 0), Eigen::Vector3d(-4 - eps, 2.9 * s, 0),
              Eigen::Vector3d(3.9 * s, 3 + eps, 0), Eigen::Vector3d(3.9 * s, -3 - eps, 0)}) {
          SurfaceHit hit;
          const Ray ray = RayTo(o, q);
          ASSERT_TRUE(rs.Intersect(ray, &hit));
          EXPECT_EQ(hit.geom, eps > 0 ? ground : floor) << q.transpose();
          // a shadow ray ending 1 mm above the point is not blocked; 10 % longer, it crosses
          // the floor or the ground.
          Ray shadow = RayTo(o, q + Eigen::Vector3d(0, 0, 1e-3));
          shadow.tmax = 1.0f;
          EXPECT_FALSE(rs.Occluded(shadow));
          shadow.tmax = 1.1f;  // goes on through the floor or the ground
          EXPECT_TRUE(rs.Occluded(shadow));
        }
      }
    }
  }
  EXPECT_GT(checked, 7000);
}

TEST(RaySceneTest, InfinitePlanesAtGrazingAnglesKeepFloatDepths) {
  // an infinite floor and an infinite wall (posed with a rotation whose matrix has rounding
  // residues instead of zeros), seen at grazing angles out to 1e4 m: the depth is the
  // analytic one to float rounding at every distance, and shadow rays leaving the hit point
  // away from the surface are never blocked by it (no self-intersection).
  SceneDescription scene = EmptyScene();
  const Pose X_floor = Translation(0, 0, 0);
  Pose X_wall = Translation(30, 0, 0);
  X_wall.linear() = Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  ASSERT_NE(X_wall.linear()(0, 0), 0.0);  // a rotation with rounding residues
  const int floor = AddGeom(&scene, GeomShape::kPlane, {0, 0, 1}, X_floor);
  const int wall = AddGeom(&scene, GeomShape::kPlane, {0, 0, 1}, X_wall);
  RayScene rs(scene);
  rs.Update(testing::IdentitySnapshot(scene));
  const Eigen::Vector3d o(0.3, -0.2, 0.35);
  int floor_hits = 0, wall_hits = 0;
  for (int i = 0; i < 400; ++i) {
    // elevation from -0.5 rad down to -5e-5 rad (floor hits out to 7e3 m) and azimuths
    // all around (rays towards +x meet the wall first).
    const double el = -0.5 * std::pow(10.0, -4.0 * i / 399.0);
    const double az = 2 * M_PI * i * 0.618034;
    Ray ray;
    ray.o = o.cast<float>();
    ray.d = Eigen::Vector3d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el))
                .cast<float>();
    SurfaceHit hit;
    double t_floor, t_wall;
    Eigen::Vector3d p_floor, p_wall;
    const bool h_floor = ReferencePlaneHit(X_floor, kInfinitePlaneHalfSize, kInfinitePlaneHalfSize,
                                           ray, &t_floor, &p_floor);
    const bool h_wall = ReferencePlaneHit(X_wall, kInfinitePlaneHalfSize, kInfinitePlaneHalfSize,
                                          ray, &t_wall, &p_wall);
    if (!h_floor && !h_wall) {
      EXPECT_FALSE(rs.Intersect(ray, &hit));
      continue;
    }
    ASSERT_TRUE(rs.Intersect(ray, &hit)) << i;
    const bool wall_first = h_wall && (!h_floor || t_wall < t_floor);
    ASSERT_EQ(hit.geom, wall_first ? wall : floor) << i;
    if (wall_first) {
      ExpectPlaneHit(hit, ray, X_wall, t_wall, p_wall);
      ++wall_hits;
    } else {
      ExpectPlaneHit(hit, ray, X_floor, t_floor, p_floor);
      ++floor_hits;
    }
    // the hit point itself lies on the plane to float rounding of p_W.
    const double dist = wall_first ? hit.p_W.x() - 30.0 : hit.p_W.z();
    EXPECT_LT(std::abs(dist), 3e-7 * (hit.p_W.cwiseAbs().maxCoeff() + o.cwiseAbs().maxCoeff()));
    // shadow rays towards the sky side never hit their own surface.
    for (const Eigen::Vector3f& d :
         {Eigen::Vector3f(hit.ng_W), Eigen::Vector3f(hit.ng_W + 0.3f * ray.d).normalized(),
          Eigen::Vector3f(-ray.d)}) {
      Ray shadow = SpawnRay(hit, d);
      shadow.tmax = 1e-2f;
      EXPECT_FALSE(rs.Occluded(shadow)) << i;
    }
  }
  EXPECT_GT(floor_hits, 200);
  EXPECT_GT(wall_hits, 30);
}

TEST(RaySceneTest, TiltedPlanesStayAnalytic) {
  // a tilted infinite plane (30 deg about x and 20 deg about z) and a tilted finite one: the
  // depth is the analytic one to float rounding of the ray, also 1e3 m away, and shadow rays
  // from the hits leave the surface (no self-intersection).
  SceneDescription scene = EmptyScene();
  Pose X_big = Translation(0.5, 1.0, -1.0);
  X_big.linear() = (Eigen::AngleAxisd(0.35, Eigen::Vector3d::UnitZ()) *
                    Eigen::AngleAxisd(0.52, Eigen::Vector3d::UnitX()))
                       .toRotationMatrix();
  const int big = AddGeom(&scene, GeomShape::kPlane, {0, 0, 1}, X_big);
  RayScene rs(scene);
  rs.Update(testing::IdentitySnapshot(scene));
  const Eigen::Vector3d n_W = X_big.linear().col(2);
  int hits = 0;
  for (int i = 0; i < 500; ++i) {
    const double u = -1 + 2.0 * ((i * 37) % 500) / 500, v = -1 + 2.0 * i / 500;
    // targets on the plane out to 1e3 m from its centre, and a ray origin above it.
    const Eigen::Vector3d target = X_big * Eigen::Vector3d(1e3 * u * u * u, 1e3 * v * v * v, 0);
    const Eigen::Vector3d o = X_big * Eigen::Vector3d(0.2, -0.1, 1.3);
    const Ray ray = RayTo(o, target);
    double t;
    Eigen::Vector3d p_G;
    ASSERT_TRUE(
        ReferencePlaneHit(X_big, kInfinitePlaneHalfSize, kInfinitePlaneHalfSize, ray, &t, &p_G));
    SurfaceHit hit;
    ASSERT_TRUE(rs.Intersect(ray, &hit));
    EXPECT_EQ(hit.geom, big);
    ExpectPlaneHit(hit, ray, X_big, t, p_G);
    Ray shadow = SpawnRay(hit, n_W.cast<float>());
    EXPECT_FALSE(rs.Occluded(shadow));
    ++hits;
  }
  EXPECT_EQ(hits, 500);
}

TEST(RaySceneTest, PlaneOnAMovingBodyMatchesTheAnalyticPlane) {
  // a finite 0.6 x 0.4 m plate on a moving body (a robot's deck), posed with rotations; it is
  // axis-aligned in the body frame: hits match the analytic plane posed at
  // X_WB X_BG, rays 1e-4 m past an edge miss, and packets (IntersectMany, OccludedLanes)
  // agree with single rays.
  SceneDescription scene = EmptyScene();
  const int body = AddBody(&scene, "deck");
  Pose X_BG = Translation(0.1, -0.05, 0.2);
  X_BG.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const int plate = AddGeom(&scene, GeomShape::kPlane, {0.6, 0.4, 0.01}, X_BG, body);
  RayScene rs(scene);
  WorldSnapshot snap = testing::IdentitySnapshot(scene);
  int hits = 0, misses = 0;
  for (const double yaw : {0.0, 0.4, -2.2}) {
    Pose X_WB = Translation(2.0, 0.3, 0.5);
    X_WB.linear() = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                     Eigen::AngleAxisd(0.2 * yaw, Eigen::Vector3d::UnitY()))
                        .toRotationMatrix();
    snap.X_WB[body] = X_WB;
    rs.Update(snap);
    const Pose X_WG = X_WB * X_BG;
    const Eigen::Vector3d o(0, 0, 0.4);
    std::vector<Ray> rays;
    std::vector<int> expect;  // 1 hit, 0 miss
    for (int i = -12; i <= 12; ++i)
      for (int j = -12; j <= 12; ++j) {
        // a grid over the plate and its edges: targets at 0.9 of the half-size, and
        // 1e-4 m beyond the edges.
        const double x = i == 12 ? 0.6 + 1e-4 : i == -12 ? -0.6 - 1e-4 : 0.9 * 0.6 * i / 11;
        const double y = j == 12 ? 0.4 + 1e-4 : j == -12 ? -0.4 - 1e-4 : 0.9 * 0.4 * j / 11;
        rays.push_back(RayTo(o, X_WG * Eigen::Vector3d(x, y, 0)));
        expect.push_back(std::abs(i) < 12 && std::abs(j) < 12);
      }
    const int n = static_cast<int>(rays.size());
    std::vector<SurfaceHit> many(n);
    std::unique_ptr<bool[]> got_many(new bool[n]);
    rs.IntersectMany(rays.data(), n, /*coherent=*/true, many.data(), got_many.get());
    for (int k = 0; k < n; ++k) {
      SurfaceHit hit;
      const bool got = rs.Intersect(rays[k], &hit);
      ASSERT_EQ(got, expect[k] == 1) << "ray " << k << " yaw " << yaw;
      ASSERT_EQ(got_many[k], got);
      Ray shadow = rays[k];
      shadow.tmax = 1.0f - 1e-3f;  // ends 0.1 % before the plate
      EXPECT_FALSE(rs.Occluded(shadow));
      shadow.tmax = 1.0f + 1e-3f;
      EXPECT_EQ(rs.Occluded(shadow), got);
      if (!got) {
        ++misses;
        continue;
      }
      ++hits;
      EXPECT_EQ(hit.geom, plate);
      ExpectSameHit(many[k], hit);
      double t;
      Eigen::Vector3d p_G;
      ASSERT_TRUE(ReferencePlaneHit(X_WG, 0.6, 0.4, rays[k], &t, &p_G));
      ExpectPlaneHit(hit, rays[k], X_WG, t, p_G);
    }
    // the same shadow rays as lanes.
    for (int start = 0; start + kLanes <= n; start += kLanes) {
      Vec3Lanes lo, ld;
      Lanes tmax;
      for (int k = 0; k < kLanes; ++k) {
        const Ray& r = rays[start + k];
        lo.x[k] = r.o.x();
        lo.y[k] = r.o.y();
        lo.z[k] = r.o.z();
        ld.x[k] = r.d.x();
        ld.y[k] = r.d.y();
        ld.z[k] = r.d.z();
        tmax[k] = k % 2 ? 1.0f + 1e-3f : 1.0f - 1e-3f;
      }
      const LaneMask active(0xbfffu);  // lane 14 idle
      LaneMask occluded;
      rs.OccludedLanes(lo, ld, tmax, active, &occluded);
      for (int k = 0; k < kLanes; ++k)
        EXPECT_EQ(occluded[k], k != 14 && k % 2 == 1 && expect[start + k] == 1) << start + k;
    }
  }
  EXPECT_GT(hits, 1000);
  EXPECT_GT(misses, 250);
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

// anisotropic texture filtering's inputs: a textured mesh on a turned body reports its
// triangles' texcoord gradient in the geom frame and the ray direction in the geom frame, and an
// analytic shape the ray direction in its frame.
TEST(RaySceneTest, HitsCarryTexcoordGradientAndGeomFrameDirection) {
  SceneDescription scene = EmptyScene();
  const int body = AddBody(&scene, "arm");
  TriangleMesh plate = Plate(4);
  // u = 2 (x + 0.5), v = 3 (y + 0.5): du/dx = 2, dv/dy = 3.
  for (const Eigen::Vector3f& p : plate.vertices)
    plate.texcoords.emplace_back(2 * (p.x() + 0.5f), 3 * (p.y() + 0.5f));
  scene.meshes.push_back(plate);
  Pose X_BG = Translation(0, 0.1, 0);
  X_BG.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const int mesh = AddGeom(&scene, GeomShape::kMesh, {1, 1, 1}, X_BG, body);
  scene.geoms[mesh].mesh = 0;
  const int sphere = AddGeom(&scene, GeomShape::kSphere, {0.2, 0, 0}, X_BG, body);
  WorldSnapshot snap = testing::IdentitySnapshot(scene);
  Pose X_WB = Translation(0.2, -0.1, 2);
  X_WB.linear() = Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  snap.X_WB[body] = X_WB;
  RayScene rs(scene);
  rs.Update(snap);
  const Pose X_WG = X_WB * X_BG;
  const Eigen::Matrix3f R_GW = X_WG.linear().transpose().cast<float>();
  Ray ray;
  // from below and to the side: the plate (z_G = 0, facing the ray's origin side) is met first
  // at an oblique angle.
  ray.o = Eigen::Vector3f(1.5f, 0.7f, 0.0f);
  ray.d = (X_WG * Eigen::Vector3d(0.3, -0.2, 0) - ray.o.cast<double>()).cast<float>() * 2;
  SurfaceHit hit;
  ASSERT_TRUE(rs.Intersect(ray, &hit));
  ASSERT_EQ(hit.geom, mesh);
  ASSERT_TRUE(hit.has_uv);
  Eigen::Matrix<float, 2, 3> J;
  J << 2, 0, 0, 0, 3, 0;
  EXPECT_LT((hit.duv_dp_G - J).cwiseAbs().maxCoeff(), 1e-4f) << hit.duv_dp_G;
  EXPECT_LT((hit.d_G - R_GW * ray.d.normalized()).norm(), 1e-5f);
  EXPECT_NEAR(hit.uv.x(), 2 * (0.3 + 0.5), 1e-4);
  EXPECT_NEAR(hit.uv.y(), 3 * (-0.2 + 0.5), 1e-4);
  // the sphere, seen from above (the plate is below its centre's ray).
  Ray down;
  down.o = (X_WG.translation() + Eigen::Vector3d(0.05, 0.02, 1)).cast<float>();
  down.d = Eigen::Vector3f(0.1f, 0.05f, -1.0f);
  ASSERT_TRUE(rs.Intersect(down, &hit));
  ASSERT_EQ(hit.geom, sphere);
  EXPECT_FALSE(hit.has_uv);
  EXPECT_EQ(hit.duv_dp_G, (Eigen::Matrix<float, 2, 3>::Zero()));
  EXPECT_LT((hit.d_G - R_GW * down.d.normalized()).norm(), 1e-5f);
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

// a robot-mounted camera: a static room (floor, walls, a crate, a sphere), a robot body whose
// camera sits 0.5 mm in front of its housing box, a leg body that reaches into the lower right
// of the view, and a second robot walking through the view.
struct RobotCameraFixture {
  SceneDescription scene = EmptyScene();
  WorldSnapshot snapshot;
  int trunk, leg, walker;
  Pose X_WO;  // camera optical frame
  RobotCameraFixture() {
    AddGeom(&scene, GeomShape::kPlane, {0, 0, 1}, Translation(0, 0, 0));
    AddGeom(&scene, GeomShape::kBox, {0.1, 4, 1.5}, Translation(5, 0, 1.5));
    AddGeom(&scene, GeomShape::kBox, {4, 0.1, 1.5}, Translation(1, 3, 1.5));
    AddGeom(&scene, GeomShape::kBox, {0.3, 0.3, 0.3}, Translation(3, -1, 0.3));
    AddGeom(&scene, GeomShape::kSphere, {0.4, 0, 0}, Translation(3.5, 1.2, 0.6));
    trunk = AddBody(&scene, "trunk");
    leg = AddBody(&scene, "leg");
    scene.bodies[leg].parent = trunk;
    walker = AddBody(&scene, "walker");
    // trunk: a box 0.4 m long ending at x = 0.2145, the camera at x = 0.215 (body frame).
    AddGeom(&scene, GeomShape::kBox, {0.19, 0.1, 0.06}, Translation(0.0245, 0, 0), trunk);
    AddGeom(&scene, GeomShape::kCylinder, {0.007, 0.0015, 0}, Translation(0.2135, 0.03, 0.0),
            trunk);
    // leg: a capsule reaching forward and down in front of the trunk's right side.
    Pose X_LG = Translation(0.4, -0.12, -0.15);
    X_LG.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY()).toRotationMatrix();
    AddGeom(&scene, GeomShape::kCapsule, {0.03, 0.12, 0}, X_LG, leg);
    AddGeom(&scene, GeomShape::kBox, {0.2, 0.2, 0.8}, Translation(0, 0, 0.8), walker);
    snapshot = testing::IdentitySnapshot(scene);
    Pose X_WT = Translation(0.5, -0.2, 0.35);
    X_WT.linear() = Eigen::AngleAxisd(0.25, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    snapshot.X_WB[trunk] = X_WT;
    snapshot.X_WB[leg] = X_WT;
    snapshot.X_WB[walker] = Translation(3.2, 0.5, 0);
    X_WO = X_WT * testing::CameraLookingAlongX(Eigen::Vector3d(0.215, 0, 0));
  }
};

TEST(RaySceneTest, RobotCameraTilesTracedStaticOnlyMatchSingleRays) {
  RobotCameraFixture f;
  RayScene rs(f.scene);
  rs.Update(f.snapshot);
  const Camera camera(f.X_WO, CameraIntrinsics::FromFovy(320, 240, 100));
  ASSERT_TRUE(camera.projective());
  int static_tiles = 0, full_tiles = 0, static_rays = 0;
  std::vector<bool> seen(f.scene.geoms.size(), false);
  for (int y0 = 0; y0 < 240; y0 += 16)
    for (int x0 = 0; x0 < 320; x0 += 16) {
      std::vector<Ray> rays;
      for (int y = y0; y < y0 + 16; ++y)
        for (int x = x0; x < x0 + 16; ++x) {
          rays.push_back(camera.GenerateRay(x, y));
          rays.back().tmin = 0.01f;
        }
      const RayCone cone =
          RayCone::FromCorners(rays[0].o, {rays[0].d, rays[15].d, rays[255].d, rays[240].d}, 0.01f);
      std::vector<SurfaceHit> single(256), grid(256), grid_rays(256);
      bool hit_single[256], hit_grid[256], hit_grid_rays[256];
      for (int i = 0; i < 256; ++i) hit_single[i] = rs.Intersect(rays[i], &single[i]);
      const bool fast = rs.IntersectGrid(rays.data(), 16, 16, grid.data(), hit_grid, &cone);
      // without a cone, RayScene bounds the rays itself (a looser cone: it may decide
      // otherwise near the robot, never with other hits).
      if (rs.IntersectGrid(rays.data(), 16, 16, grid_rays.data(), hit_grid_rays)) ++static_rays;
      (fast ? static_tiles : full_tiles)++;
      for (int i = 0; i < 256; ++i) {
        SCOPED_TRACE(::testing::Message() << "tile " << x0 << " " << y0 << " ray " << i);
        ASSERT_EQ(hit_grid[i], hit_single[i]);
        ASSERT_EQ(hit_grid_rays[i], hit_single[i]);
        if (!hit_single[i]) continue;
        seen[single[i].geom] = true;
        if (fast) {
          EXPECT_EQ(f.scene.geoms[single[i].geom].body, 0);
        }
        ExpectSameHit(grid[i], single[i]);
        ExpectSameHit(grid_rays[i], single[i]);
      }
    }
  // most tiles miss the robot's own geoms and take the static path; the leg and the walker
  // are seen (through the top level), the trunk and its lens never.
  EXPECT_GT(static_tiles, 200);
  EXPECT_GT(static_rays, 200);
  EXPECT_GT(full_tiles, 5);
  EXPECT_TRUE(seen[7]) << "leg";
  EXPECT_TRUE(seen[8]) << "walker";
  EXPECT_FALSE(seen[5]) << "trunk";
  EXPECT_FALSE(seen[6]) << "lens";
}

TEST(RaySceneTest, ShadowPacketsTracedStaticOnlyMatchSingleRays) {
  RobotCameraFixture f;
  RayScene rs(f.scene);
  rs.Update(f.snapshot);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0, 1);
  const Eigen::Vector3f lamp(1.5f, 0.5f, 2.9f);
  int static_packets = 0, full_packets = 0, occluded = 0, lit = 0;
  for (int packet = 0; packet < 400; ++packet) {
    // points on the floor and the walls towards a lamp (finite) or the sun (endless).
    const bool sun = packet % 2 == 1;
    Vec3Lanes o, d;
    Lanes tmax;
    const Eigen::Vector3f base(-0.5f + 5 * u(rng), -2.5f + 5 * u(rng), 0.001f);
    for (int k = 0; k < kLanes; ++k) {
      const Eigen::Vector3f p = base + Eigen::Vector3f(0.02f * k, 0.03f * u(rng), 0);
      o.Set(k, p);
      if (sun) {
        d.Set(k, Eigen::Vector3f(-0.4f, 0.3f + 0.01f * u(rng), 0.8f));
        tmax[k] = std::numeric_limits<float>::infinity();
      } else {
        d.Set(k, lamp - p);
        tmax[k] = 1 - 1e-4f;
      }
    }
    const LaneMask active(0xffffu & ~(1u << (packet % 16)));
    LaneMask packet_occluded;
    const bool fast = rs.OccludedLanes(o, d, tmax, active, &packet_occluded);
    (fast ? static_packets : full_packets)++;
    for (int k = 0; k < kLanes; ++k) {
      Ray r;
      r.o = o.Lane(k);
      r.d = d.Lane(k);
      r.tmax = tmax[k];
      const bool expected = active[k] && rs.Occluded(r);
      ASSERT_EQ(packet_occluded[k], expected) << "packet " << packet << " lane " << k;
      if (active[k]) (expected ? occluded : lit)++;
    }
  }
  EXPECT_GT(static_packets, 100);
  EXPECT_GT(full_packets, 10);
  EXPECT_GT(occluded, 500);
  EXPECT_GT(lit, 500);
}

}  // namespace
}  // namespace penumbra
