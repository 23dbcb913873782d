#include "penumbra/world/camera_specs.h"

#include <gtest/gtest.h>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

TEST(CameraSpecsTest, SemanticClassesFirstMatchWins) {
  SceneDescription s;
  s.bodies = {{"world", -1, true}, {"rover/chassis", 0, false}, {"arm/link", 0, false}};
  Material concrete, steel;
  concrete.name = "room/concrete_floor";
  steel.name = "steel";
  s.materials = {concrete, steel};
  auto geom = [&](const std::string& name, int body, int material) {
    Geom g;
    g.name = name;
    g.body = body;
    g.material = material;
    s.geoms.push_back(g);
  };
  geom("floor", 0, 0);
  geom("rover/wheel", 1, 1);
  geom("arm/gripper", 2, 1);
  geom("", 0, 1);
  std::vector<SemanticClassConfig> classes(3);
  classes[0] = {"robot", 1, {"rover/*"}, {}, {}};
  classes[1] = {"floor", 7, {}, {}, {"*concrete*"}};
  classes[2] = {"gripper", 9, {}, {"*gripper", "rover/*"}, {}};
  ApplySemanticClasses(classes, &s);
  EXPECT_EQ(s.geoms[0].semantic_class, 7);
  EXPECT_EQ(s.geoms[1].semantic_class, 1);  // class 'robot' comes first
  EXPECT_EQ(s.geoms[2].semantic_class, 9);
  EXPECT_EQ(s.geoms[3].semantic_class, 0);
}

TEST(CameraSpecsTest, StereoCameraBecomesTwoWithBaselineAlongOpticalX) {
  CameraConfig c;
  c.name = "head";
  c.k1 = -0.1;
  c.sensor.exposure_time_sec = 0.004;
  c.sensor.stereo_baseline_m = 0.1;
  CameraSpec cam;
  cam.name = "head";
  cam.intrinsics = CameraIntrinsics::FromFovy(64, 48, 60);
  cam.X_BO.linear() = RotationBodyFromOptical();
  cam.X_BO.translation() = Eigen::Vector3d(0.2, 0, 0.5);
  std::vector<CameraSpec> out;
  AppendWorldCamera(c, cam, &out);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].name, "head/left");
  EXPECT_EQ(out[1].name, "head/right");
  EXPECT_EQ(out[0].intrinsics.k1, -0.1);
  EXPECT_EQ(out[1].exposure_time_sec, 0.004);
  // optical x = body -y: the right camera sits 0.1 m towards body -y
  EXPECT_TRUE(out[1].X_BO.translation().isApprox(Eigen::Vector3d(0.2, -0.1, 0.5)));
  EXPECT_TRUE(out[1].X_BO.linear().isApprox(out[0].X_BO.linear()));
  WorldConfig w;
  w.cameras.push_back(c);
  SceneDescription s;
  s.cameras = out;
  const std::vector<CameraSensorConfig> cfg = SensorConfigsFor(s, w);
  ASSERT_EQ(cfg.size(), 2u);
  EXPECT_EQ(cfg[1].exposure_time_sec, 0.004);
}

TEST(CameraSpecsTest, FoldingDistortionOnTheFinalIntrinsicsIsAConfigError) {
  // an MJCF camera's fovy is known only after compilation: the check runs at assembly
  CameraConfig c;
  c.name = "rover/head";
  c.k1 = -0.5;
  CameraSpec cam;
  cam.name = c.name;
  cam.intrinsics = CameraIntrinsics::FromFovy(640, 480, 100);
  try {
    ApplyCameraConfig(c, &cam, "w.yaml", "mjcf_cameras.overrides.rover/head");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "mjcf_cameras.overrides.rover/head.distortion");
    EXPECT_NE(std::string(e.what()).find("camera 'rover/head'"), std::string::npos);
  }
  cam.intrinsics = CameraIntrinsics::FromFovy(640, 480, 30);
  ApplyCameraConfig(c, &cam, "w.yaml", "k");
  EXPECT_EQ(cam.intrinsics.k1, -0.5);
  // the override's sensor settings reach the MJCF camera
  c.sensor.motion_blur_samples = 5;
  WorldConfig w;
  w.mjcf_cameras.overrides.push_back(c);
  SceneDescription s;
  cam.mjcf_camera = 0;
  s.cameras = {cam};
  EXPECT_EQ(SensorConfigsFor(s, w)[0].motion_blur_samples, 5);
}

}  // namespace
}  // namespace penumbra
