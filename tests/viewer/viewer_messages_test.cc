#include "penumbra/viewer/viewer_messages.h"

#include <gtest/gtest.h>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

using nlohmann::json;

SceneDescription TinyScene() {
  SceneDescription s;
  s.bodies = {{"world", -1, true}, {"robot/trunk", 0, false}, {"robot/leg", 1, false}};
  Material red;
  red.base_color = {1.0f, 0.0f, 0.0f};
  Material hidden;
  hidden.alpha = 0.2f;
  s.materials = {red, hidden};
  Geom box;
  box.body = 1;
  box.shape = GeomShape::kBox;
  box.size = {0.1, 0.2, 0.3};
  box.X_BG = PoseFromXyzRpyDeg({1, 2, 3}, {0, 0, 90});
  box.material = 0;
  Geom ghost = box;
  ghost.material = 1;
  Geom mesh;
  mesh.body = 2;
  mesh.shape = GeomShape::kMesh;
  mesh.mesh = 0;
  mesh.material = 0;
  Geom mesh2 = mesh;  // the same mesh again: sent once
  Geom group3 = box;
  group3.group = 3;
  s.geoms = {box, ghost, mesh, mesh2, group3};
  TriangleMesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1.234567f, 0}};
  m.faces = {{0, 1, 2}};
  s.meshes = {m};
  CameraSpec cam;
  cam.name = "front";
  cam.body = 1;
  cam.X_BO = PoseFromXyzRpyDeg({0.5, 0, 0}, {0, 0, 0});
  s.cameras = {cam};
  return s;
}

TEST(ViewerMessagesTest, SceneHoldsTheVisibleGeomsOnce) {
  const json j = SceneJson(TinyScene());
  EXPECT_EQ(j["type"], "scene");
  ASSERT_EQ(j["bodies"].size(), 3u);
  EXPECT_TRUE(j["bodies"][1]["trail"]);   // moving root body
  EXPECT_FALSE(j["bodies"][2]["trail"]);  // child
  EXPECT_FALSE(j["bodies"][0]["trail"]);  // world
  ASSERT_EQ(j["geoms"].size(), 3u);       // the ghost (alpha 0.2) and group 3 are left out
  const json& b = j["geoms"][0];
  EXPECT_EQ(b["shape"], "box");
  EXPECT_EQ(b["size"], json({0.1, 0.2, 0.3}));
  EXPECT_EQ(b["pos"], json({1.0, 2.0, 3.0}));
  EXPECT_NEAR(b["quat"][0].get<double>(), std::sqrt(0.5), 1e-6);
  EXPECT_NEAR(b["quat"][3].get<double>(), std::sqrt(0.5), 1e-6);
  EXPECT_EQ(b["color"], json({1.0, 0.0, 0.0, 1.0}));
  EXPECT_EQ(j["geoms"][1]["mesh"], 0);
  EXPECT_EQ(j["geoms"][2]["mesh"], 0);
  ASSERT_EQ(j["meshes"].size(), 1u);
  EXPECT_EQ(j["meshes"][0]["f"], json({0, 1, 2}));
  EXPECT_DOUBLE_EQ(j["meshes"][0]["v"][7].get<double>(), 1.2346);
}

TEST(ViewerMessagesTest, PosesOfBodiesAndCameras) {
  const SceneDescription s = TinyScene();
  WorldSnapshot snap;
  snap.X_WB = {Pose::Identity(), PoseFromXyzRpyDeg({1, 0, 0}, {0, 0, 90}), Pose::Identity()};
  const json bodies = BodyPosesJson(snap);
  ASSERT_EQ(bodies.size(), 21u);
  EXPECT_EQ(bodies[7], 1.0);
  const json cams = CameraPosesJson(s, snap);
  // the camera 0.5 m ahead of the trunk along its x, which the yaw turns to world +y
  EXPECT_NEAR(cams["front"][0].get<double>(), 1.0, 1e-9);
  EXPECT_NEAR(cams["front"][1].get<double>(), 0.5, 1e-9);
}

TEST(ViewerMessagesTest, FrameMessagesRoundTrip) {
  const json h = {{"camera", "front"}, {"time_sec", 0.25}};
  const std::string payload("\xff\xd8\x00jpeg", 7);
  const std::string m = PackFrameMessage(h, payload);
  const auto [h2, p2] = UnpackFrameMessage(m);
  EXPECT_EQ(h2, h);
  EXPECT_EQ(p2, payload);
  EXPECT_THROW(UnpackFrameMessage("ab"), Error);
  EXPECT_THROW(UnpackFrameMessage(m.substr(0, 10)), Error);
}

}  // namespace
}  // namespace penumbra
