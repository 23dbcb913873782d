// scene/scene_limits.h: the intrinsics rule and the checks of a compiled scene (geom sizes and
// centres, mesh vertices, MJCF camera field of view and position) on hand-made scenes.

#include "penumbra/scene/scene_limits.h"

#include <gtest/gtest.h>

namespace penumbra {
namespace {

TEST(FindIntrinsicsProblem, AcceptsOrdinaryAndRejectsDegenerateIntrinsics) {
  EXPECT_FALSE(FindIntrinsicsProblem(CameraIntrinsics::FromFovy(640, 480, 60)));
  EXPECT_FALSE(FindIntrinsicsProblem(CameraIntrinsics::FromFovy(480, 480, 178.9)));
  EXPECT_TRUE(FindIntrinsicsProblem(CameraIntrinsics::FromFovy(480, 480, 179.1)));
  // the horizontal field of view counts too: square pixels at 640 x 480 and fovy 178.9 reach
  // 179.2 deg across
  EXPECT_TRUE(FindIntrinsicsProblem(CameraIntrinsics::FromFovy(640, 480, 178.9)));

  CameraIntrinsics k = CameraIntrinsics::FromFovy(32, 24, 60);
  k.cx = 1e300;
  ASSERT_TRUE(FindIntrinsicsProblem(k));
  EXPECT_NE(FindIntrinsicsProblem(k)->find("horizontal field of view"), std::string::npos);
  k = CameraIntrinsics::FromFovy(32, 24, 60);
  k.fx = k.fy = 1e-300;
  EXPECT_TRUE(FindIntrinsicsProblem(k));
  k = CameraIntrinsics::FromFovy(32, 24, 60);
  k.cy = std::numeric_limits<double>::quiet_NaN();
  ASSERT_TRUE(FindIntrinsicsProblem(k));
  EXPECT_EQ(FindIntrinsicsProblem(k)->rfind("cy is nan", 0), 0u) << *FindIntrinsicsProblem(k);
  k = CameraIntrinsics::FromFovy(32, 24, 60);
  k.fx = 0;
  EXPECT_TRUE(FindIntrinsicsProblem(k));
}

// a world body and one body with one geom; the snapshot poses body 1 at `body_pos`.
struct OneGeom {
  SceneDescription scene;
  WorldSnapshot initial;
  OneGeom(GeomShape shape, const Eigen::Vector3d& size, const Eigen::Vector3d& body_pos) {
    scene.bodies.resize(2);
    scene.bodies[1].name = "m/ball";
    scene.bodies[1].parent = 0;
    Geom g;
    g.name = "m/ball";
    g.body = 1;
    g.shape = shape;
    g.size = size;
    scene.geoms.push_back(g);
    initial.X_WB.assign(2, Pose::Identity());
    initial.X_WB[1].translation() = body_pos;
  }
};

TEST(FindSceneLimitProblem, GeomSizes) {
  EXPECT_FALSE(FindSceneLimitProblem(OneGeom(GeomShape::kSphere, {0.2, 0, 0}, {0, 0, 1}).scene,
                                     OneGeom(GeomShape::kSphere, {0.2, 0, 0}, {0, 0, 1}).initial));
  const OneGeom huge(GeomShape::kSphere, {1e30, 0, 0}, {0, 0, 1});
  const auto p = FindSceneLimitProblem(huge.scene, huge.initial);
  ASSERT_TRUE(p);
  EXPECT_EQ(p->object, "geom 'm/ball'");
  EXPECT_EQ(p->body, "m/ball");
  EXPECT_EQ(p->problem, "size[0] is 1e+30 m; expected [1e-06, 100000] m");
  const OneGeom tiny(GeomShape::kBox, {0.1, 1e-9, 0.1}, {0, 0, 1});
  ASSERT_TRUE(FindSceneLimitProblem(tiny.scene, tiny.initial));
  EXPECT_EQ(FindSceneLimitProblem(tiny.scene, tiny.initial)->problem.rfind("size[1] is 1e-09", 0),
            0u);
  // planes: 0 = infinite
  const OneGeom plane(GeomShape::kPlane, {0, 0, 0.1}, {0, 0, 0});
  EXPECT_FALSE(FindSceneLimitProblem(plane.scene, plane.initial));
  const OneGeom big_plane(GeomShape::kPlane, {1e6, 1, 0.1}, {0, 0, 0});
  EXPECT_TRUE(FindSceneLimitProblem(big_plane.scene, big_plane.initial));
}

TEST(FindSceneLimitProblem, GeomCentresAtTheInitialPose) {
  const OneGeom far(GeomShape::kSphere, {0.2, 0, 0}, {1e19, 0, 0});
  const auto p = FindSceneLimitProblem(far.scene, far.initial);
  ASSERT_TRUE(p);
  EXPECT_EQ(p->problem,
            "centre x is 1e+19 m at the initial pose; expected each coordinate in [-100000, "
            "100000] m");
  const OneGeom edge(GeomShape::kSphere, {0.2, 0, 0}, {0, -1e5, 0});
  EXPECT_FALSE(FindSceneLimitProblem(edge.scene, edge.initial));
}

TEST(FindSceneLimitProblem, MeshVertices) {
  OneGeom m(GeomShape::kMesh, {0, 0, 0}, {0, 0, 0});
  TriangleMesh mesh;
  mesh.name = "m/hull";
  mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 3e30f, 0}};
  mesh.faces = {{0, 1, 2}};
  m.scene.meshes.push_back(mesh);
  m.scene.geoms[0].mesh = 0;
  const auto p = FindSceneLimitProblem(m.scene, m.initial);
  ASSERT_TRUE(p);
  EXPECT_NE(p->problem.find("mesh 'm/hull' has a vertex coordinate of 3e+30 m"), std::string::npos)
      << p->problem;
}

TEST(FindSceneLimitProblem, MjcfCameraFieldOfView) {
  OneGeom s(GeomShape::kSphere, {0.2, 0, 0}, {0, 0, 1});
  CameraSpec cam;
  cam.name = "m/eye";
  cam.body = 1;
  cam.mjcf_camera = 0;
  // as physics/scene_extractor.cc extracts MJCF fovy="180": fy = 240 / tan(90 deg)
  cam.intrinsics = CameraIntrinsics::FromFovy(640, 480, 180);
  s.scene.cameras.push_back(cam);
  s.initial.X_W_mjcam.assign(1, Pose::Identity());
  const auto p = FindSceneLimitProblem(s.scene, s.initial);
  ASSERT_TRUE(p);
  EXPECT_EQ(p->object, "MJCF camera 'm/eye'");
  EXPECT_EQ(p->problem, "fovy is 180 deg; expected [0.1, 179) deg, as for world-file cameras");
  // skipped when the world disables MJCF cameras
  EXPECT_FALSE(FindSceneLimitProblem(s.scene, s.initial, /*mjcf_cameras=*/false));
  // a good fovy, but the camera sits far away
  s.scene.cameras[0].intrinsics = CameraIntrinsics::FromFovy(640, 480, 45);
  EXPECT_FALSE(FindSceneLimitProblem(s.scene, s.initial));
  s.initial.X_W_mjcam[0].translation() = Eigen::Vector3d(0, 0, 3e5);
  ASSERT_TRUE(FindSceneLimitProblem(s.scene, s.initial));
  EXPECT_EQ(FindSceneLimitProblem(s.scene, s.initial)->problem.rfind("position z is 300000 m", 0),
            0u);
}

}  // namespace
}  // namespace penumbra
