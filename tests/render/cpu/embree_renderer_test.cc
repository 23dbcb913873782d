// geometry of rendered images: exact depth, projection, segmentation, instancing,
// all geom shapes, determinism across thread counts.

#include "penumbra/render/cpu/embree_renderer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <set>

#include "penumbra/core/error.h"
#include "penumbra/render/camera/camera.h"
#include "render/render_test_util.h"

namespace penumbra {
namespace {

using namespace penumbra::testing;

constexpr double kDeg = M_PI / 180.0;

// a large box whose -x face lies at world x = d, filling the view of a camera at the origin.
SceneDescription WallAt(double d) {
  SceneDescription s = EmptyScene();
  AddGeom(&s, GeomShape::kBox, {0.5, 50, 50}, Translation(d + 0.5, 0, 0));
  return s;
}

TEST(EmbreeRendererTest, DepthOfBoxFaceIsExactZ) {
  for (double d : {0.3, 1.0, 2.718, 7.5, 25.0}) {
    SceneDescription s = WallAt(d);
    auto r = MakeEmbreeRenderer(s, TestSettings());
    CameraView view = MakeView(CameraLookingAlongX(), 64, 48, 70, false, true, false);
    RenderedFrame f;
    r->Render(IdentitySnapshot(s), view, &f);
    ASSERT_EQ(f.depth_m.width, 64);
    // every pixel, centre and corners included: z-depth, not range.
    for (int v = 0; v < 48; ++v)
      for (int u = 0; u < 64; ++u)
        ASSERT_NEAR(*f.depth_m.at(u, v), d, 1e-3) << "d " << d << " at " << u << "," << v;
    // and much tighter than the 1 mm requirement at the centre and a corner.
    EXPECT_NEAR(*f.depth_m.at(32, 24), d, 1e-5 * d);
    EXPECT_NEAR(*f.depth_m.at(0, 0), d, 1e-5 * d);
  }
}

TEST(EmbreeRendererTest, NearClipHidesOnlyWhatIsNearerThanNearM) {
  // a wall 6 mm in front of the camera is clipped by the default near_m (1 cm), seen with
  // near_m = 0 or 5 mm; with it clipped, the wall 2 m behind it shows (z-depth, every pixel).
  SceneDescription s = WallAt(2.0);
  AddGeom(&s, GeomShape::kBox, {0.0005, 1, 1}, Translation(0.0065, 0, 0));
  auto r = MakeEmbreeRenderer(s, TestSettings());
  CameraView view = MakeView(CameraLookingAlongX(), 32, 24, 70, false, true, false);
  EXPECT_DOUBLE_EQ(view.near_m, 0.01);
  for (double near_m : {0.01, 0.005, 0.0}) {
    view.near_m = near_m;
    RenderedFrame f;
    r->Render(IdentitySnapshot(s), view, &f);
    const double expected = near_m > 0.006 ? 2.0 : 0.006;
    for (int v = 0; v < 24; ++v)
      for (int u = 0; u < 32; ++u)
        ASSERT_NEAR(*f.depth_m.at(u, v), expected, 1e-5) << "near_m " << near_m;
  }
  view.near_m = -0.001;
  RenderedFrame f;
  EXPECT_THROW(r->Render(IdentitySnapshot(s), view, &f), Error);
}

TEST(EmbreeRendererTest, DepthOfTiltedCameraIsZNotRange) {
  // camera yawed by 20 degrees towards the wall's normal: the wall plane x = d in the optical
  // frame has z(u, v) varying linearly across the image; check against the analytic value.
  const double d = 3.0, yaw = 20 * kDeg;
  SceneDescription s = WallAt(d);
  auto r = MakeEmbreeRenderer(s, TestSettings());
  Pose X_WO = CameraLookingAlongX();
  X_WO.linear() =
      Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() * X_WO.linear();
  CameraView view = MakeView(X_WO, 80, 60, 60, false, true, false);
  RenderedFrame f;
  r->Render(IdentitySnapshot(s), view, &f);
  const CameraIntrinsics& k = view.intrinsics;
  for (int v : {0, 30, 59})
    for (int u : {0, 17, 40, 79}) {
      // ray direction in the world for optical (x, y, 1); the hit at x_W = d has z = t.
      const Eigen::Vector3d dir =
          X_WO.linear() * Eigen::Vector3d((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1);
      const double t = d / dir.x();
      EXPECT_NEAR(*f.depth_m.at(u, v), t, 1e-3) << u << "," << v;
    }
}

TEST(EmbreeRendererTest, PointProjectsWhereIntrinsicsPredict) {
  SceneDescription s = EmptyScene();
  const Eigen::Vector3d c_W(2.5, 0.4, -0.3);
  const int g =
      AddGeom(&s, GeomShape::kSphere, {0.04, 0, 0}, Translation(c_W.x(), c_W.y(), c_W.z()));
  auto r = MakeEmbreeRenderer(s, TestSettings());
  const Pose X_WO = CameraLookingAlongX(Eigen::Vector3d(0, 0.1, 0));
  CameraView view = MakeView(X_WO, 320, 240, 50, false, false, true);
  RenderedFrame f;
  r->Render(IdentitySnapshot(s), view, &f);
  int count = 0;
  const Eigen::Vector2d centroid = MaskCentroid(f.geom_id, s.geoms[g].id, &count);
  ASSERT_GT(count, 20);
  // by hand: optical x = -(y_W - 0.1), optical y = -z_W, z = x_W.
  const CameraIntrinsics& k = view.intrinsics;
  const double x = -(c_W.y() - 0.1), y = -c_W.z(), z = c_W.x();
  EXPECT_NEAR(centroid.x(), k.fx * x / z + k.cx, 0.5);
  EXPECT_NEAR(centroid.y(), k.fy * y / z + k.cy, 0.5);
  // and Camera::Project agrees.
  Eigen::Vector2d uv;
  double depth;
  ASSERT_TRUE(Camera(X_WO, k).Project(c_W, &uv, &depth));
  EXPECT_NEAR((uv - centroid).norm(), 0.0, 0.5);
  EXPECT_NEAR(depth, z, 1e-12);
}

TEST(EmbreeRendererTest, SegmentationIdsAreGeomIdsAndExactAtEdges) {
  // two boxes side by side in the plane x = 2 (left half and right half of the image, with
  // a gap of sky between them), each pixel compared with the analytic ray / box test.
  SceneDescription s = EmptyScene();
  const int a = AddGeom(&s, GeomShape::kBox, {0.1, 0.5, 0.4}, Translation(2.1, 0.6, 0.0));
  const int b = AddGeom(&s, GeomShape::kBox, {0.1, 0.3, 0.3}, Translation(2.1, -0.45, 0.1));
  auto r = MakeEmbreeRenderer(s, TestSettings(2));
  CameraView view = MakeView(CameraLookingAlongX(), 97, 73, 60, false, true, true);
  RenderedFrame f;
  r->Render(IdentitySnapshot(s), view, &f);
  const CameraIntrinsics& k = view.intrinsics;
  int checked = 0;
  for (int v = 0; v < 73; ++v)
    for (int u = 0; u < 97; ++u) {
      // slab test of the pixel-centre ray against the box grown or shrunk by `margin`.
      const Eigen::Vector3d dir(1, -(u - k.cx) / k.fx, -(v - k.cy) / k.fy);
      auto inside = [&](int gi, double margin) {
        const Geom& g = s.geoms[gi];
        const Eigen::Vector3d lo =
            g.X_BG.translation() - g.size.array().matrix() + Eigen::Vector3d::Constant(margin);
        const Eigen::Vector3d hi =
            g.X_BG.translation() + g.size - Eigen::Vector3d::Constant(margin);
        double t0 = 0, t1 = 1e9;
        for (int i = 0; i < 3; ++i) {
          double a = lo[i] / dir[i], b = hi[i] / dir[i];
          if (a > b) std::swap(a, b);
          t0 = std::max(t0, a);
          t1 = std::min(t1, b);
        }
        return t0 < t1;
      };
      const int id = *f.geom_id.at(u, v);
      ASSERT_TRUE(id == -1 || id == s.geoms[a].id || id == s.geoms[b].id) << id;
      const double m = 1e-4;  // skip pixels whose centre ray grazes an edge
      if (inside(a, m)) {
        EXPECT_EQ(id, s.geoms[a].id);
        ++checked;
      } else if (inside(b, m)) {
        EXPECT_EQ(id, s.geoms[b].id);
        ++checked;
      } else if (!inside(a, -m) && !inside(b, -m)) {
        EXPECT_EQ(id, -1);
        EXPECT_EQ(*f.depth_m.at(u, v), 0.0f);
        ++checked;
      }
    }
  EXPECT_GT(checked, 97 * 73 - 20);
}

TEST(EmbreeRendererTest, MovingABodyMovesItsPixelsWithoutRebuild) {
  SceneDescription s = EmptyScene();
  const int body = AddBody(&s, "ball");
  const int g = AddGeom(&s, GeomShape::kSphere, {0.1, 0, 0}, Translation(0.0, 0.0, 0.05), body);
  EmbreeRenderer r(s, TestSettings());
  CameraView view = MakeView(CameraLookingAlongX(), 160, 120, 60, false, true, true);
  const CameraIntrinsics& k = view.intrinsics;
  WorldSnapshot snap = IdentitySnapshot(s);
  RenderedFrame f;
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(3, 0, -0.05), Eigen::Vector3d(3, 0.5, 0.25),
                                   Eigen::Vector3d(2, -0.4, -0.3)}) {
    const int64_t commits = r.ray_scene().num_top_level_commits();
    snap.X_WB[body] = Translation(p.x(), p.y(), p.z());
    r.Render(snap, view, &f);
    EXPECT_EQ(r.ray_scene().num_top_level_commits(), commits + 1);
    int count = 0;
    const Eigen::Vector2d c = MaskCentroid(f.geom_id, s.geoms[g].id, &count);
    ASSERT_GT(count, 10);
    const Eigen::Vector3d c_W = p + Eigen::Vector3d(0, 0, 0.05);
    EXPECT_NEAR(c.x(), k.fx * -c_W.y() / c_W.x() + k.cx, 0.5);
    EXPECT_NEAR(c.y(), k.fy * -c_W.z() / c_W.x() + k.cy, 0.5);
    // exact depth at the pixel nearest the centre: smallest root of |t dir - c|^2 = r^2 for the
    // pixel's ray dir with optical z = 1 (so t is the z-depth).
    const int u = static_cast<int>(std::lround(c.x())), v = static_cast<int>(std::lround(c.y()));
    const Eigen::Vector3d dir =
        view.X_WO.linear() * Eigen::Vector3d((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1);
    const double b = dir.dot(c_W), a = dir.squaredNorm();
    const double t = (b - std::sqrt(b * b - a * (c_W.squaredNorm() - 0.01))) / a;
    EXPECT_NEAR(*f.depth_m.at(u, v), t, 1e-4);
  }
  // the same snapshot again commits nothing.
  const int64_t commits = r.ray_scene().num_top_level_commits();
  r.Render(snap, view, &f);
  EXPECT_EQ(r.ray_scene().num_top_level_commits(), commits);
}

// renders one geom straight ahead at distance d along +x and returns the depth at the image centre.
double CentreDepth(GeomShape shape, const Eigen::Vector3d& size, const Pose& X_WG,
                   SceneDescription* s_out = nullptr) {
  SceneDescription s = EmptyScene();
  AddGeom(&s, shape, size, X_WG);
  if (s_out) *s_out = s;
  auto r = MakeEmbreeRenderer(s, TestSettings());
  // odd size: the centre pixel's ray is exactly the optical axis.
  CameraView view = MakeView(CameraLookingAlongX(), 41, 31, 40, false, true, true);
  RenderedFrame f;
  r->Render(IdentitySnapshot(s), view, &f);
  EXPECT_EQ(*f.geom_id.at(20, 15), 100) << "centre pixel must see the geom";
  return *f.depth_m.at(20, 15);
}

TEST(EmbreeRendererTest, AnalyticShapesHaveExactDepth) {
  const double d = 3.0;
  const Pose at = Translation(d, 0, 0);
  // sphere r: d - r.
  EXPECT_NEAR(CentreDepth(GeomShape::kSphere, {0.37, 0, 0}, at), d - 0.37, 1e-4);
  // ellipsoid, radii (0.2, 0.5, 0.3): the x radius faces the camera.
  EXPECT_NEAR(CentreDepth(GeomShape::kEllipsoid, {0.2, 0.5, 0.3}, at), d - 0.2, 1e-4);
  // cylinder along z (seen from the side): d - r; rotated to lie along x (cap facing): d - h.
  EXPECT_NEAR(CentreDepth(GeomShape::kCylinder, {0.25, 0.6, 0}, at), d - 0.25, 1e-4);
  Pose along_x = at;
  along_x.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  EXPECT_NEAR(CentreDepth(GeomShape::kCylinder, {0.25, 0.6, 0}, along_x), d - 0.6, 1e-4);
  // capsule from the side: d - r; along x: d - h - r (hemisphere tip).
  EXPECT_NEAR(CentreDepth(GeomShape::kCapsule, {0.15, 0.4, 0}, at), d - 0.15, 1e-4);
  EXPECT_NEAR(CentreDepth(GeomShape::kCapsule, {0.15, 0.4, 0}, along_x), d - 0.55, 1e-4);
  // plane rotated to face the camera (its +z towards -x): depth d.
  Pose facing = at;
  facing.linear() = Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  EXPECT_NEAR(CentreDepth(GeomShape::kPlane, {1, 1, 0}, facing), d, 1e-4);
  EXPECT_NEAR(CentreDepth(GeomShape::kPlane, {0, 0, 0}, facing), d, 1e-4);  // infinite
  // box: d - hx.
  EXPECT_NEAR(CentreDepth(GeomShape::kBox, {0.3, 0.4, 0.5}, at), d - 0.3, 1e-4);
}

TEST(EmbreeRendererTest, SphereSilhouetteIsAnalytic) {
  // a pixel is inside the sphere's mask iff its ray passes within r of the centre.
  const Eigen::Vector3d c(2.0, 0.1, -0.05);
  const double radius = 0.3;
  SceneDescription s = EmptyScene();
  AddGeom(&s, GeomShape::kSphere, {radius, 0, 0}, Translation(c.x(), c.y(), c.z()));
  auto r = MakeEmbreeRenderer(s, TestSettings());
  CameraView view = MakeView(CameraLookingAlongX(), 90, 70, 45, false, true, true);
  RenderedFrame f;
  r->Render(IdentitySnapshot(s), view, &f);
  const Pose& X_WO = view.X_WO;
  const CameraIntrinsics& k = view.intrinsics;
  int inside = 0;
  for (int v = 0; v < 70; ++v)
    for (int u = 0; u < 90; ++u) {
      const Eigen::Vector3d dir =
          (X_WO.linear() * Eigen::Vector3d((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1)).normalized();
      const double miss =
          (c - c.dot(dir) * dir).norm();  // distance of the ray line from the centre
      if (std::abs(miss - radius) < 1e-4) continue;
      const bool hit = *f.geom_id.at(u, v) == 100;
      EXPECT_EQ(hit, miss < radius) << u << "," << v;
      if (hit) {
        // exact depth along the ray: range = c.d - sqrt(r^2 - miss^2), z = range * (dir . optical
        // z).
        const double range = c.dot(dir) - std::sqrt(radius * radius - miss * miss);
        EXPECT_NEAR(*f.depth_m.at(u, v), range * dir.dot(X_WO.linear().col(2)), 1e-4);
        ++inside;
      }
    }
  EXPECT_GT(inside, 100);
}

TEST(EmbreeRendererTest, MeshAndHeightFieldRender) {
  SceneDescription s = EmptyScene();
  // a tetrahedron-like mesh: a square pyramid whose apex points at the camera.
  TriangleMesh mesh;
  mesh.name = "pyramid";
  mesh.vertices = {
      {0, 0, 0.3f}, {-0.2f, -0.2f, 0}, {0.2f, -0.2f, 0}, {0.2f, 0.2f, 0}, {-0.2f, 0.2f, 0}};
  mesh.faces = {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {0, 4, 1}, {1, 4, 3}, {1, 3, 2}};
  s.meshes.push_back(mesh);
  Pose X = Translation(2, 0, 0);
  X.linear() =
      Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();  // +z -> -x
  const int gm = AddGeom(&s, GeomShape::kMesh, {0, 0, 0}, X);
  s.geoms[gm].mesh = 0;
  // a flat height field at elevation 0.5 facing the camera, beside the pyramid.
  HeightField hf;
  hf.name = "flat";
  hf.rows = 3;
  hf.cols = 5;
  hf.size_x = 0.2;
  hf.size_y = 0.2;
  hf.size_z = 0.1;
  hf.size_base = 0.05;
  hf.elevation.assign(15, 0.5f);
  s.hfields.push_back(hf);
  Pose Xh = X;
  Xh.translation() = Eigen::Vector3d(2, -0.5, 0);
  const int gh = AddGeom(&s, GeomShape::kHeightField, {0, 0, 0}, Xh);
  s.geoms[gh].hfield = 0;
  auto r = MakeEmbreeRenderer(s, TestSettings());
  CameraView view = MakeView(CameraLookingAlongX(), 81, 41, 40, false, true, true);
  RenderedFrame f;
  r->Render(IdentitySnapshot(s), view, &f);
  const CameraIntrinsics& k = view.intrinsics;
  // the centre pixel (40, 20) looks exactly at the pyramid's apex, world (1.7, 0, 0).
  EXPECT_EQ(*f.geom_id.at(40, 20), s.geoms[gm].id);
  EXPECT_NEAR(*f.depth_m.at(40, 20), 1.7, 1e-4);
  // the height field's top (elevation 0.5 x 0.1 towards the camera) is at world x = 1.95.
  const int uh = static_cast<int>(std::lround(0.5 / 1.95 * k.fx + k.cx));
  EXPECT_EQ(*f.geom_id.at(uh, 20), s.geoms[gh].id);
  EXPECT_NEAR(*f.depth_m.at(uh, 20), 1.95, 1e-4);
  // its base and side walls: seen from behind (the camera on the far side), the bottom face
  // lies at local z = -0.05, i.e. world x = 2.05.
  CameraView back = view;
  back.X_WO = Pose::Identity();
  back.X_WO.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
                       CameraLookingAlongX().linear();
  back.X_WO.translation() = Eigen::Vector3d(4, 0, 0);
  r->Render(IdentitySnapshot(s), back, &f);
  const int ub = static_cast<int>(std::lround(-0.5 / 1.95 * k.fx + k.cx));  // image x = +y_W now
  EXPECT_EQ(*f.geom_id.at(ub, 20), s.geoms[gh].id);
  EXPECT_NEAR(*f.depth_m.at(ub, 20), 4 - 2.05, 1e-4);
}

TEST(EmbreeRendererTest, HiddenGroupsAndTransparentMaterialsAreSkipped) {
  SceneDescription s = EmptyScene();
  const int g0 = AddGeom(&s, GeomShape::kSphere, {0.5, 0, 0}, Translation(2, 0, 0));
  s.geoms[g0].group = 3;
  const int m = AddMaterial(&s, {1, 1, 1});
  s.materials[m].alpha = 0.2f;
  AddGeom(&s, GeomShape::kSphere, {0.5, 0, 0}, Translation(3, 0, 0), 0, m);
  const int g2 = AddGeom(&s, GeomShape::kBox, {0.1, 1, 1}, Translation(4, 0, 0));
  auto r = MakeEmbreeRenderer(s, TestSettings());
  RenderedFrame f;
  r->Render(IdentitySnapshot(s), MakeView(CameraLookingAlongX(), 21, 21, 30), &f);
  EXPECT_EQ(*f.geom_id.at(10, 10), s.geoms[g2].id);
  EXPECT_NEAR(*f.depth_m.at(10, 10), 3.9, 1e-4);
}

// a small furnished scene with soft lights and textures for the determinism test.
SceneDescription BusyScene() {
  SceneDescription s = EmptyScene();
  s.sky.radiance = {0.3f, 0.35f, 0.4f};
  Texture tex;
  tex.name = "checker";
  std::vector<uint8_t> rgb;
  for (int i = 0; i < 16; ++i) {
    const uint8_t c = ((i % 4) + (i / 4)) % 2 ? 230 : 40;
    rgb.insert(rgb.end(), {c, c, static_cast<uint8_t>(c / 2)});
  }
  tex.image = std::make_shared<const TextureImage>(4, 4, 1, std::move(rgb));
  s.textures.push_back(tex);
  const int floor = AddMaterial(&s, {0.8f, 0.8f, 0.8f}, 0.6f, 0.0f, 0.5f);
  s.materials[floor].texture = 0;
  s.materials[floor].texuniform = true;
  const int metal = AddMaterial(&s, {0.9f, 0.6f, 0.3f}, 0.3f, 1.0f, 0.5f);
  const int red = AddMaterial(&s, {0.7f, 0.1f, 0.1f}, 0.4f, 0.0f, 0.5f);
  AddGeom(&s, GeomShape::kPlane, {0, 0, 1}, Pose::Identity(), 0, floor);
  const int body = AddBody(&s, "robot");
  AddGeom(&s, GeomShape::kCapsule, {0.1, 0.3, 0}, Translation(0, 0, 0.4), body, metal);
  AddGeom(&s, GeomShape::kBox, {0.2, 0.2, 0.2}, Translation(0.6, 0.4, 0.2), 0, red);
  AddGeom(&s, GeomShape::kSphere, {0.15, 0, 0}, Translation(-0.5, 0.3, 0.15), 0, metal);
  AddGeom(&s, GeomShape::kCylinder, {0.1, 0.2, 0}, Translation(0.3, -0.5, 0.2), 0, red);
  Light sun;
  sun.type = Light::Type::kDirectional;
  sun.direction_B = Eigen::Vector3d(0.3, 0.2, -1).normalized();
  sun.intensity = 5000;
  sun.angular_radius_deg = 2;
  s.lights.push_back(sun);
  Light lamp;
  lamp.type = Light::Type::kPoint;
  lamp.position_B = {0.5, -0.5, 1.5};
  lamp.intensity = 200;
  lamp.radius_m = 0.1;
  s.lights.push_back(lamp);
  Light spot;
  spot.type = Light::Type::kSpot;
  spot.body = body;
  spot.position_B = {0, 0, 1.2};
  spot.direction_B = {0, 0, -1};
  spot.intensity = 500;
  spot.radius_m = 0.05;
  s.lights.push_back(spot);
  return s;
}

TEST(EmbreeRendererTest, ThreadCountDoesNotChangeTheImage) {
  SceneDescription s = BusyScene();
  RenderSettings one = TestSettings(1);
  one.auto_exposure = true;
  one.tone_map = RenderSettings::ToneMap::kFilmic;
  RenderSettings two = one;
  two.threads = 2;
  auto r1 = MakeEmbreeRenderer(s, one);
  auto r2 = MakeEmbreeRenderer(s, two);
  Pose X_WO = CameraLookingAlongX(Eigen::Vector3d(-2.5, 0, 1.2));
  X_WO.linear() =
      Eigen::AngleAxisd(20 * kDeg, Eigen::Vector3d::UnitY()).toRotationMatrix() * X_WO.linear();
  CameraView view = MakeView(X_WO, 67, 45, 60);  // not a multiple of the tile size
  view.frame_index = 3;
  WorldSnapshot snap = IdentitySnapshot(s);
  snap.X_WB[1] = Translation(0.1, 0.1, 0);
  RenderedFrame a, b;
  r1->Render(snap, view, &a);
  r2->Render(snap, view, &b);
  ASSERT_EQ(a.rgb.data.size(), b.rgb.data.size());
  EXPECT_EQ(0, std::memcmp(a.rgb.data.data(), b.rgb.data.data(), a.rgb.data.size()));
  EXPECT_EQ(0, std::memcmp(a.radiance.data.data(), b.radiance.data.data(),
                           a.radiance.data.size() * sizeof(float)));
  EXPECT_EQ(0, std::memcmp(a.depth_m.data.data(), b.depth_m.data.data(),
                           a.depth_m.data.size() * sizeof(float)));
  EXPECT_EQ(a.geom_id.data, b.geom_id.data);
  EXPECT_EQ(a.ev100, b.ev100);
  EXPECT_EQ(a.rays, b.rays);
  // the image is not trivially uniform, and a different frame index changes nothing: the soft
  // shadows have no per-frame noise.
  std::set<uint8_t> values(a.rgb.data.begin(), a.rgb.data.end());
  EXPECT_GT(values.size(), 50u);
  view.frame_index = 4;
  RenderedFrame c;
  r1->Render(snap, view, &c);
  EXPECT_EQ(a.geom_id.data, c.geom_id.data);
  EXPECT_EQ(0, std::memcmp(a.radiance.data.data(), c.radiance.data.data(),
                           a.radiance.data.size() * sizeof(float)));
}

TEST(EmbreeRendererTest, OnlyRequestedOutputsAreFilled) {
  SceneDescription s = WallAt(2);
  auto r = MakeEmbreeRenderer(s, TestSettings());
  RenderedFrame f;
  r->Render(IdentitySnapshot(s), MakeView(CameraLookingAlongX(), 16, 12, 60, false, true, false),
            &f);
  EXPECT_TRUE(f.rgb.empty());
  EXPECT_TRUE(f.radiance.empty());
  EXPECT_TRUE(f.geom_id.empty());
  EXPECT_EQ(f.depth_m.data.size(), 16u * 12u);
  EXPECT_EQ(f.rays, 16 * 12);
}

TEST(EmbreeRendererTest, StaticBodiesArePosedBySnapshot) {
  // static bodies are merged into one world-frame scene built from the snapshot's poses, and
  // rebuilt if a static pose ever changes.
  SceneDescription s = EmptyScene();
  const int shelf = AddBody(&s, "shelf", /*is_static=*/true);
  const int g = AddGeom(&s, GeomShape::kBox, {0.1, 0.5, 0.5}, Translation(0.5, 0, 0), shelf);
  EmbreeRenderer r(s, TestSettings());
  WorldSnapshot snap = IdentitySnapshot(s);
  RenderedFrame f;
  const CameraView view = MakeView(CameraLookingAlongX(), 21, 21, 30);
  for (double x : {2.0, 3.0}) {
    snap.X_WB[shelf] = Translation(x, 0, 0);
    r.Render(snap, view, &f);
    EXPECT_EQ(*f.geom_id.at(10, 10), s.geoms[g].id);
    EXPECT_NEAR(*f.depth_m.at(10, 10), x + 0.4, 1e-4);
  }
}

TEST(EmbreeRendererTest, EmptySceneShowsTheSky) {
  SceneDescription s = EmptyScene();
  AddBody(&s, "empty");
  s.sky.radiance = {1, 2, 3};
  auto r = MakeEmbreeRenderer(s, TestSettings());
  RenderedFrame f;
  r->Render(IdentitySnapshot(s), MakeView(CameraLookingAlongX(), 8, 6, 60), &f);
  for (int v = 0; v < 6; ++v)
    for (int u = 0; u < 8; ++u) {
      EXPECT_EQ(*f.geom_id.at(u, v), -1);
      EXPECT_EQ(*f.depth_m.at(u, v), 0.0f);
      EXPECT_FLOAT_EQ(f.radiance.at(u, v)[2], 3.0f);
    }
}

TEST(EmbreeRendererTest, MismatchedSnapshotThrows) {
  SceneDescription s = WallAt(2);
  auto r = MakeEmbreeRenderer(s, TestSettings());
  WorldSnapshot snap;
  snap.X_WB.assign(3, Pose::Identity());
  RenderedFrame f;
  EXPECT_THROW(r->Render(snap, MakeView(CameraLookingAlongX(), 8, 8, 60), &f), Error);
}

TEST(EmbreeRendererTest, BadReferencesThrow) {
  SceneDescription s = EmptyScene();
  const int g = AddGeom(&s, GeomShape::kMesh, {0, 0, 0}, Pose::Identity());
  s.geoms[g].mesh = 5;
  EXPECT_THROW(MakeEmbreeRenderer(s, TestSettings()), Error);
  SceneDescription s2 = EmptyScene();
  AddGeom(&s2, GeomShape::kSphere, {-1, 0, 0}, Pose::Identity());
  EXPECT_THROW(MakeEmbreeRenderer(s2, TestSettings()), Error);
}

}  // namespace
}  // namespace penumbra
