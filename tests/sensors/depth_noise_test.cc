#include "penumbra/sensors/depth_noise.h"

#include <gtest/gtest.h>

#include <cmath>

#include "camera_sensor_test_util.h"
#include "penumbra/core/error.h"
#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/render/renderer.h"
#include "penumbra/sensors/camera_imager.h"

namespace penumbra {
namespace {

using testing::AddGeom;
using testing::AddMaterial;
using testing::BlackScene;

// a large grey wall facing a camera at the origin looking along +x, at distance z.
SceneDescription Wall(double z) {
  SceneDescription s = BlackScene();
  const int m = AddMaterial(&s, Eigen::Vector3f(0.5f, 0.5f, 0.5f));
  AddGeom(&s, GeomShape::kBox, Eigen::Vector3d(0.01, 20, 20), Eigen::Vector3d(z + 0.01, 0, 0), m);
  return s;
}

struct DepthStats {
  double mean = 0, std = 0, model_rms = 0;
  int valid = 0;
};

DepthStats MeasureWall(const std::string& preset, double z) {
  const SceneDescription scene = Wall(z);
  RenderSettings rs;
  rs.tier = RenderSettings::Tier::kRealtime;
  auto renderer = MakeRenderer(scene, rs);
  CameraSpec spec;
  spec.name = "rgbd";
  spec.intrinsics = CameraIntrinsics::FromFovy(160, 120, 40);
  spec.outputs = CameraOutputs{ImageKind::kDepth};
  CameraSensorConfig cfg;
  cfg.depth_noise.preset = preset;
  CameraImager imager(spec, cfg, rs, 0, scene);
  const WorldSnapshot snap = testing::Snapshot(scene, 0);
  CameraImages img;
  imager.Capture(renderer.get(), snap, nullptr, testing::LookingAlongX(Eigen::Vector3d::Zero()),
                 nullptr, Pose::Identity(), 3, &img);
  const DepthNoiseModel model = DepthNoisePreset(cfg.depth_noise, "d");
  DepthStats st;
  double s = 0, s2 = 0, m2 = 0;
  const CameraIntrinsics& k = spec.intrinsics;
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const float d = *img.depth_m.at(u, v);
      EXPECT_NEAR(*img.truth.depth_m.at(u, v), z, 1e-5 * z);
      if (!(d > 0)) continue;
      ++st.valid;
      s += d;
      s2 += d * d;
      const double theta = std::atan(std::hypot((u - k.cx) / k.fx, (v - k.cy) / k.fy));
      const double sz = model.AxialSigma(z, theta, k.fx);
      m2 += sz * sz;
    }
  }
  st.mean = s / st.valid;
  st.std = std::sqrt(std::max(0.0, s2 / st.valid - st.mean * st.mean));
  st.model_rms = std::sqrt(m2 / st.valid);
  return st;
}

TEST(DepthNoiseTest, WallNoiseMatchesPresetModels) {
  struct Case {
    const char* preset;
    double z;
  };
  for (const Case c :
       {Case{"realsense_d435", 1}, Case{"realsense_d435", 2}, Case{"realsense_d435", 4},
        Case{"kinect_v1", 1}, Case{"kinect_v1", 2}, Case{"kinect_v1", 3.9}, Case{"kinect_v2", 1},
        Case{"kinect_v2", 2}, Case{"kinect_v2", 4}}) {
    const DepthStats st = MeasureWall(c.preset, c.z);
    std::printf("%-15s z %.1f m: valid %d mean %.5f std %.3f mm, model %.3f mm (%.1f%%)\n",
                c.preset, c.z, st.valid, st.mean, 1e3 * st.std, 1e3 * st.model_rms,
                100 * (st.std / st.model_rms - 1));
    EXPECT_EQ(st.valid, 160 * 120) << c.preset;
    EXPECT_NEAR(st.mean, c.z, 3 * st.model_rms / std::sqrt(st.valid) + 1e-5);
    EXPECT_NEAR(st.std, st.model_rms, 0.10 * st.model_rms) << c.preset << " at " << c.z;
  }
}

TEST(DepthNoiseTest, RangeLimitsAndGrazingAnglesDropReturns) {
  DepthNoiseConfig cfg;
  cfg.preset = "kinect_v1";
  const DepthNoiseModel m = DepthNoisePreset(cfg, "d");
  ImageF depth(4, 1, 1);
  *depth.at(0, 0) = 0.3f;  // too close
  *depth.at(1, 0) = 5.0f;  // too far
  *depth.at(2, 0) = 2.0f;  // grazing (normal perpendicular to the ray)
  *depth.at(3, 0) = 2.0f;  // fine
  ImageF normals(4, 1, 3);
  const float grazing[3] = {1, 0, 0}, facing[3] = {0, 0, -1};
  for (int u = 0; u < 4; ++u)
    std::copy(u == 2 ? grazing : facing, (u == 2 ? grazing : facing) + 3, normals.at(u, 0));
  DepthNoiseInputs in;
  in.normal_O = &normals;
  in.cx = 0;  // rays through pixel u have x = u / fx ~ 0: the z axis
  ImageF out;
  ApplyDepthNoise(depth, in, m, 1, &out);
  EXPECT_EQ(*out.at(0, 0), 0.0f);
  EXPECT_EQ(*out.at(1, 0), 0.0f);
  EXPECT_EQ(*out.at(2, 0), 0.0f);
  EXPECT_NEAR(*out.at(3, 0), 2.0f, 0.05f);
}

TEST(DepthNoiseTest, DarkAndSpecularSurfacesDropReturns) {
  DepthNoiseConfig cfg;
  cfg.preset = "realsense_d435";
  const DepthNoiseModel m = DepthNoisePreset(cfg, "d");
  ImageF depth(3, 1, 1, 1.0f), refl(3, 1, 1);
  *refl.at(0, 0) = 0.01f;  // dark
  *refl.at(1, 0) = -1.0f;  // specular
  *refl.at(2, 0) = 0.5f;
  DepthNoiseInputs in;
  in.reflectance = &refl;
  ImageF out;
  ApplyDepthNoise(depth, in, m, 1, &out);
  EXPECT_EQ(*out.at(0, 0), 0.0f);
  EXPECT_EQ(*out.at(1, 0), 0.0f);
  EXPECT_GT(*out.at(2, 0), 0.9f);
}

TEST(DepthNoiseTest, FogDropsReturnsWithRoundTripTransmittance) {
  // homogeneous fog sigma = 0.2 / m; wall at 2 m: T = exp(-0.4), keep probability T^2 = exp(-0.8)
  HomogeneousMedium fog;
  fog.sigma_t_per_m = Eigen::Vector3f(0.2f, 0.2f, 0.2f);
  EXPECT_NEAR(HomogeneousOpticalDepth(fog, Eigen::Vector3d::Zero(), Eigen::Vector3d(2, 0, 0)), 0.4,
              1e-6);
  fog.region = BoxRegion{Eigen::Vector3d(1, -1, -1), Eigen::Vector3d(1.5, 1, 1)};
  EXPECT_NEAR(HomogeneousOpticalDepth(fog, Eigen::Vector3d::Zero(), Eigen::Vector3d(2, 0, 0)), 0.1,
              1e-6);
  fog.region.reset();
  EffectsFrame fx;
  fx.homogeneous_media.push_back(fog);
  const CameraIntrinsics k = CameraIntrinsics::FromFovy(100, 100, 1);  // near-parallel rays
  const Camera cam(testing::LookingAlongX(Eigen::Vector3d::Zero()), k);
  const ImageF depth(100, 100, 1, 2.0f);
  const ImageF t = DepthTransmittance(depth, cam, fx, 1);
  EXPECT_NEAR(*t.at(50, 50), std::exp(-0.4), 1e-4);
  DepthNoiseConfig cfg;
  cfg.preset = "realsense_d435";
  const DepthNoiseModel m = DepthNoisePreset(cfg, "d");
  DepthNoiseInputs in;
  in.transmittance = &t;
  in.fx = k.fx;
  ImageF out;
  ApplyDepthNoise(depth, in, m, 9, &out);
  int kept = 0;
  for (float d : out.data) kept += d > 0;
  const double p = std::exp(-0.8);
  EXPECT_NEAR(kept / 1e4, p, 4 * std::sqrt(p * (1 - p) / 1e4));
  // thick smoke: below the threshold every return is lost
  fog.sigma_t_per_m = Eigen::Vector3f(2, 2, 2);
  fx.homogeneous_media = {fog};
  const ImageF t2 = DepthTransmittance(depth, cam, fx, 1);
  in.transmittance = &t2;
  ApplyDepthNoise(depth, in, m, 9, &out);
  for (float d : out.data) EXPECT_EQ(d, 0.0f);
}

TEST(DepthNoiseTest, SmokeGridTransmittanceByRatioTracking) {
  // a 1 m smoke box of density 1, sigma_t 0.5 / m across the rays: mean T = exp(-0.5)
  EffectsFrame fx;
  GridMedium g;
  g.X_WG.translation() = Eigen::Vector3d(1.5, 0, 0);
  g.half_extents_m = Eigen::Vector3d(0.5, 2, 2);
  g.nx = g.ny = g.nz = 4;
  g.density = std::make_shared<const std::vector<float>>(64, 1.0f);
  g.max_density = 1.0f;
  g.sigma_t_per_m = Eigen::Vector3f(0.5f, 0.5f, 0.5f);
  fx.grid_media.push_back(g);
  const CameraIntrinsics k = CameraIntrinsics::FromFovy(100, 100, 1);
  const Camera cam(testing::LookingAlongX(Eigen::Vector3d::Zero()), k);
  const ImageF t = DepthTransmittance(ImageF(100, 100, 1, 3.0f), cam, fx, 5);
  double mean = 0;
  for (float v : t.data) mean += v / 1e4;
  EXPECT_NEAR(mean, std::exp(-0.5), 0.01);
}

TEST(DepthNoiseTest, LateralNoiseJagsEdges) {
  // a step edge: with lateral noise some pixels next to it read the other side's depth
  DepthNoiseConfig cfg;
  cfg.preset = "kinect_v2";
  const DepthNoiseModel m = DepthNoisePreset(cfg, "d");
  ImageF depth(40, 40, 1);
  for (int v = 0; v < 40; ++v)
    for (int u = 0; u < 40; ++u) *depth.at(u, v) = u < 20 ? 1.0f : 2.0f;
  DepthNoiseInputs in;
  in.cx = in.cy = 20;
  ImageF out;
  ApplyDepthNoise(depth, in, m, 3, &out);
  int swapped = 0;
  for (int v = 0; v < 40; ++v) swapped += *out.at(19, v) > 1.5f || *out.at(20, v) < 1.5f;
  EXPECT_GT(swapped, 5);
  for (int v = 0; v < 40; ++v) EXPECT_LT(*out.at(5, v), 1.5f);  // far from the edge: unaffected
}

TEST(DepthNoiseTest, UnknownPresetNamesTheKey) {
  DepthNoiseConfig cfg;
  cfg.preset = "kinect_v3";
  try {
    DepthNoisePreset(cfg, "cameras[head].depth_noise");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "cameras[head].depth_noise.preset");
    EXPECT_NE(std::string(e.what()).find("realsense_d435"), std::string::npos);
  }
}

}  // namespace
}  // namespace penumbra
