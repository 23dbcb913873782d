// camera profiles (sensors/camera_profile.h): photon transfer statistics of each profile's
// sensor, the ideal profile's bytes, auto exposure at its limits, optics, and determinism
// across thread counts.
#include "penumbra/sensors/camera_profile.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "camera_sensor_test_util.h"
#include "penumbra/core/error.h"
#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/sensors/camera_imager.h"
#include "penumbra/sensors/image_noise.h"

namespace penumbra {
namespace {

using testing::AddGeom;
using testing::AddMaterial;
using testing::LookingAlongX;
using testing::Snapshot;

struct PtcMoments {
  double mean = 0, var = 0;
};

PtcMoments PtcOf(const std::vector<double>& v) {
  PtcMoments m;
  for (double x : v) m.mean += x;
  m.mean /= v.size();
  for (double x : v) m.var += (x - m.mean) * (x - m.mean);
  m.var /= v.size() - 1;
  return m;
}

// EMVA 1288 photon transfer: two frames of a uniform exposure; the mean of their average and
// half the variance of their difference (the fixed pattern cancels) against
//   mu_y = K (mu_e + mu_d),  sigma_y^2 = K^2 (sigma_r^2 + mu_e + mu_d) + 1/12
// with mu_d = dark current x T and K the profile's ADC gain at analog gain g.
TEST(CameraProfileTest, TemporalNoiseFollowsEachProfilesPhotonTransferCurve) {
  constexpr int kSide = 200;
  const double T = 0.02;
  for (CameraProfile p : {CameraProfile::kRealsenseD435Rgb, CameraProfile::kBlackflySImx250}) {
    const ImageNoiseConfig base = CameraProfileConfig(p).noise;
    ASSERT_TRUE(base.enabled);
    for (double gain : {1.0, 4.0}) {
      ImageNoiseConfig c = base;
      c.iso = c.base_iso * gain;
      const double K = GainDnPerElectron(c);
      for (double fill : {0.02, 0.1, 0.3, 0.6}) {  // fraction of the full well at this gain
        SCOPED_TRACE(std::string(CameraProfileName(p)) + " gain " + std::to_string(gain) +
                     " fill " + std::to_string(fill));
        // exposed value x: mu_e = x full_well / gain electrons
        ImageF exposed(kSide, kSide, 1, static_cast<float>(fill));
        ImageF a, b;
        ApplyImageNoise(exposed, c, 11, &a, nullptr, T, 99);
        ApplyImageNoise(exposed, c, 12, &b, nullptr, T, 99);
        std::vector<double> avg, diff;
        for (size_t i = 0; i < a.data.size(); ++i) {
          avg.push_back(0.5 * (a.data[i] + b.data[i]));
          diff.push_back(a.data[i] - b.data[i]);
        }
        const double mu_e = fill * c.full_well_e / gain;
        const double mu_d = c.dark_current_e_per_s * T;
        const double mean = K * (mu_e + mu_d);
        const double var = K * K * (c.read_noise_e * c.read_noise_e + mu_e + mu_d) + 1.0 / 12;
        EXPECT_NEAR(PtcOf(avg).mean, mean, 0.05 * mean);
        EXPECT_NEAR(0.5 * PtcOf(diff).var, var, 0.05 * var);
      }
    }
  }
}

TEST(CameraProfileTest, FixedPatternIsTheSameEveryFrameAndHasTheProfilesSpread) {
  // the spatial variance of the mean of many frames: the fixed pattern K^2 (PRNU^2 mu_e^2 +
  // DSNU^2) plus what is left of the temporal noise (1 / frames of it)
  const ImageNoiseConfig c = CameraProfileConfig(CameraProfile::kRealsenseD435Rgb).noise;
  const double K = GainDnPerElectron(c), fill = 0.5, T = 0.01;
  constexpr int kFrames = 16, kSide = 160;
  ImageF exposed(kSide, kSide, 1, static_cast<float>(fill));
  std::vector<double> sum(kSide * kSide, 0.0);
  for (int f = 0; f < kFrames; ++f) {
    ImageF dn;
    ApplyImageNoise(exposed, c, HashKeys(5, f), &dn, nullptr, T, 77);
    for (size_t i = 0; i < sum.size(); ++i) sum[i] += dn.data[i] / kFrames;
  }
  const double mu_e = fill * c.full_well_e;
  const double temporal =
      K * K * (c.read_noise_e * c.read_noise_e + mu_e + c.dark_current_e_per_s * T) + 1.0 / 12;
  const double fixed = K * K * (c.prnu * c.prnu * mu_e * mu_e + c.dsnu_e * c.dsnu_e);
  const double expected = fixed + temporal / kFrames;
  EXPECT_NEAR(PtcOf(sum).var, expected, 0.05 * expected);
  // another fixed-pattern key (another camera) gives another pattern, the same one its own
  ImageF a, b, other;
  ApplyImageNoise(exposed, c, 1, &a, nullptr, T, 77);
  ApplyImageNoise(exposed, c, 1, &b, nullptr, T, 77);
  ApplyImageNoise(exposed, c, 1, &other, nullptr, T, 78);
  EXPECT_EQ(a.data, b.data);
  EXPECT_NE(a.data, other.data);
}

TEST(CameraProfileTest, DarkCurrentGrowsWithExposureTime) {
  ImageNoiseConfig c = CameraProfileConfig(CameraProfile::kRealsenseD435Rgb).noise;
  c.dark_current_e_per_s = 1000;  // e-/s, so that 0.1 s gives 100 e-
  const double K = GainDnPerElectron(c);
  ImageF black(100, 100, 1, 0.0f), dn;
  for (double T : {0.0, 0.1}) {
    ApplyImageNoise(black, c, 3, &dn, nullptr, T, 4);
    std::vector<double> v(dn.data.begin(), dn.data.end());
    // clipping at 0 raises the mean of a pure read-noise frame a little
    EXPECT_NEAR(PtcOf(v).mean, K * c.dark_current_e_per_s * T, T > 0 ? 0.05 * K * 100 : 0.5);
  }
}

TEST(CameraProfileTest, NamesAreAClosedSetAndIdealIsTheDefault) {
  EXPECT_EQ(CameraProfileNames(), "ideal, realsense_d435_rgb, blackfly_s_imx250");
  for (const CameraProfileEntry& e : kCameraProfiles) {
    ASSERT_TRUE(FindCameraProfile(e.name));
    EXPECT_EQ(*FindCameraProfile(e.name), e.id);
    EXPECT_EQ(CameraProfileName(e.id), e.name);
    EXPECT_EQ(CameraProfileConfig(e.id).profile, e.id);
    EXPECT_NO_THROW(ValidateCameraSensorOrThrow(CameraProfileConfig(e.id), "cameras[x]"));
  }
  EXPECT_FALSE(FindCameraProfile("realsense"));
  const CameraSensorConfig ideal = CameraProfileConfig(CameraProfile::kIdeal), def;
  EXPECT_FALSE(ideal.noise.enabled);
  EXPECT_FALSE(ideal.auto_exposure.enabled);
  EXPECT_EQ(ideal.optics.vignetting_exponent, 0);
  EXPECT_EQ(ideal.optics.psf_sigma_px, 0);
  EXPECT_EQ(ideal.optics.lateral_ca_px, 0);
  EXPECT_EQ(ideal.motion_blur_samples, def.motion_blur_samples);
  EXPECT_EQ(ideal.rolling_shutter_line_time_sec, 0);
  EXPECT_EQ(ideal.rolling_shutter_readout_sec, 0);
  EXPECT_EQ(ideal.exposure_time_sec, def.exposure_time_sec);
  // the saturation-based ISO of a pixel: 78 / H_sat
  EXPECT_NEAR(SaturationIso(4090, 1.0, 1.0), 78.0, 1e-9);
  EXPECT_NEAR(CameraProfileConfig(CameraProfile::kBlackflySImx250).noise.base_iso,
              78.0 / (10500 / (0.64 * 3.45 * 3.45 * 4090)), 1e-9);
}

// a lit room corner: a grey floor and wall under a sun, with a bright emissive panel
SceneDescription LitRoom(float sun_lux, float panel_cd_m2) {
  SceneDescription s = testing::BlackScene();
  s.sky.radiance = Eigen::Vector3f::Constant(sun_lux > 0 ? 0.05f * sun_lux / 10 : 0.0f);
  const int grey = AddMaterial(&s, Eigen::Vector3f(0.5f, 0.5f, 0.5f));
  const int red = AddMaterial(&s, Eigen::Vector3f(0.7f, 0.1f, 0.1f));
  const int panel =
      AddMaterial(&s, Eigen::Vector3f::Zero(), Eigen::Vector3f::Constant(panel_cd_m2));
  AddGeom(&s, GeomShape::kBox, {10, 10, 0.05}, {0, 0, -0.05}, grey);
  AddGeom(&s, GeomShape::kBox, {0.05, 10, 3}, {6, 0, 3}, grey);
  AddGeom(&s, GeomShape::kSphere, {0.5, 0, 0}, {3, 0.5, 0.5}, red);
  AddGeom(&s, GeomShape::kBox, {0.02, 0.3, 0.3}, {5.9, -1.5, 1.5}, panel);
  Light sun;
  sun.type = Light::Type::kDirectional;
  sun.direction_B = Eigen::Vector3d(0.3, 0.2, -1).normalized();
  sun.intensity = sun_lux;
  if (sun_lux > 0) s.lights.push_back(sun);
  return s;
}

CameraSpec ProfileSpec(int w, int h) {
  CameraSpec spec;
  spec.name = "cam";
  spec.intrinsics = CameraIntrinsics::FromFovy(w, h, 60);
  spec.outputs = CameraOutputs{ImageKind::kRgb, ImageKind::kDepth};
  return spec;
}

RenderSettings ProfileRealtime(int threads) {
  RenderSettings rs;
  rs.tier = RenderSettings::Tier::kRealtime;
  rs.threads = threads;
  rs.seed = 3;
  return rs;
}

CameraImages ProfileCapture(const SceneDescription& scene, const CameraSensorConfig& cfg,
                            int threads, int frames = 1) {
  const RenderSettings rs = ProfileRealtime(threads);
  auto renderer = MakeRenderer(scene, rs);
  CameraImager imager(ProfileSpec(160, 120), cfg, rs, 0, scene);
  const Pose X0 = LookingAlongX({0, 0, 1});
  Pose X1 = X0;
  X1.translation() += Eigen::Vector3d(0.02, 0.05, 0);
  const WorldSnapshot a = Snapshot(scene, 0), b = Snapshot(scene, 0.08);
  CameraImages img;
  for (int f = 0; f < frames; ++f) imager.Capture(renderer.get(), a, nullptr, X0, &b, X1, f, &img);
  return img;
}

double MeanCode(const ImageU8& img) {
  double s = 0;
  for (uint8_t v : img.data) s += v;
  return s / img.data.size();
}

TEST(CameraProfileTest, IdealGivesTheRenderersOwnImage) {
  const SceneDescription scene = LitRoom(2000, 8e3);
  const RenderSettings rs = ProfileRealtime(2);
  auto renderer = MakeRenderer(scene, rs);
  CameraImager imager(ProfileSpec(160, 120), CameraProfileConfig(CameraProfile::kIdeal), rs, 0,
                      scene);
  CameraImages img;
  const WorldSnapshot a = Snapshot(scene, 0);
  imager.Capture(renderer.get(), a, nullptr, LookingAlongX({0, 0, 1}), nullptr, Pose::Identity(), 0,
                 &img);
  // what the renderer develops itself, without any camera model
  CameraView view;
  view.X_WO = LookingAlongX({0, 0, 1});
  view.intrinsics = ProfileSpec(160, 120).intrinsics;
  view.exposure_time_sec = 0.01;
  view.outputs = CameraOutputs{ImageKind::kRgb};
  RenderedFrame direct;
  renderer->Render(a, nullptr, view, &direct);
  EXPECT_EQ(img.rgb.data, direct.rgb.data);
  EXPECT_EQ(img.analog_gain, 1);
}

TEST(CameraProfileTest, SameBytesForAnyThreadCount) {
  const SceneDescription scene = LitRoom(2000, 8e3);
  for (CameraProfile p : {CameraProfile::kRealsenseD435Rgb, CameraProfile::kBlackflySImx250}) {
    const CameraImages one = ProfileCapture(scene, CameraProfileConfig(p), 1, 2);
    const CameraImages three = ProfileCapture(scene, CameraProfileConfig(p), 3, 2);
    EXPECT_EQ(one.rgb.data, three.rgb.data) << CameraProfileName(p);
    EXPECT_EQ(one.exposure_time_sec, three.exposure_time_sec);
    // ground truth stays exact: a still real camera's depth is the ideal one's
    const WorldSnapshot a = Snapshot(scene, 0);
    auto renderer = MakeRenderer(scene, ProfileRealtime(1));
    CameraImages real, ideal;
    CameraImager(ProfileSpec(160, 120), CameraProfileConfig(p), ProfileRealtime(1), 0, scene)
        .Capture(renderer.get(), a, nullptr, LookingAlongX({0, 0, 1}), nullptr, Pose::Identity(), 0,
                 &real);
    CameraImager(ProfileSpec(160, 120), CameraSensorConfig(), ProfileRealtime(1), 0, scene)
        .Capture(renderer.get(), a, nullptr, LookingAlongX({0, 0, 1}), nullptr, Pose::Identity(), 0,
                 &ideal);
    EXPECT_EQ(real.depth_m.data, ideal.depth_m.data);
    EXPECT_NE(real.rgb.data, ideal.rgb.data);
  }
}

TEST(CameraProfileTest, LowLightRaisesGainAndNoiseThenDarkensAtTheLimits) {
  const CameraSensorConfig d435 = CameraProfileConfig(CameraProfile::kRealsenseD435Rgb);
  struct Level {
    float lux;
    CameraImages img;
  };
  std::vector<Level> levels = {{20000, {}}, {200, {}}, {2, {}}, {0.02f, {}}};
  for (Level& l : levels) l.img = ProfileCapture(LitRoom(l.lux, 0), d435, 2, 1);
  // bright: short shutter, unit gain; dim: gain up; darkest: both at their limits
  EXPECT_LT(levels[0].img.exposure_time_sec, d435.auto_exposure.max_exposure_time_sec);
  EXPECT_EQ(levels[0].img.analog_gain, 1);
  EXPECT_EQ(levels[3].img.exposure_time_sec, d435.auto_exposure.max_exposure_time_sec);
  EXPECT_EQ(levels[3].img.analog_gain, d435.auto_exposure.max_gain);
  // the frame-to-frame noise of a static scene: the std of two frames' difference
  auto noise = [&](float lux) {
    const SceneDescription scene = LitRoom(lux, 0);
    const RenderSettings rs = ProfileRealtime(2);
    auto renderer = MakeRenderer(scene, rs);
    CameraImager imager(ProfileSpec(160, 120), d435, rs, 0, scene);
    CameraImages f0, f1;
    const WorldSnapshot a = Snapshot(scene, 0);
    imager.Capture(renderer.get(), a, nullptr, LookingAlongX({0, 0, 1}), nullptr, Pose::Identity(),
                   0, &f0);
    imager.Capture(renderer.get(), a, nullptr, LookingAlongX({0, 0, 1}), nullptr, Pose::Identity(),
                   1, &f1);
    std::vector<double> d;
    for (size_t i = 0; i < f0.rgb.data.size(); ++i) d.push_back(f0.rgb.data[i] - f1.rgb.data[i]);
    return std::sqrt(0.5 * PtcOf(d).var);
  };
  const double n_bright = noise(20000), n_dim = noise(2);
  EXPECT_GT(n_dim, 1.5 * n_bright);
  // past the limits the image gets darker with the light
  EXPECT_LT(MeanCode(levels[3].img.rgb), 0.5 * MeanCode(levels[2].img.rgb));
  EXPECT_LT(MeanCode(levels[2].img.rgb), MeanCode(levels[0].img.rgb));
}

TEST(CameraProfileTest, HighlightsRollOffInsteadOfClipping) {
  // a large panel some 25x brighter than the sunlit floor (a sunlit window): the ideal film
  // flattens it at 255; the profiles' exposure and tone curve keep it below full scale
  SceneDescription scene = LitRoom(2000, 8e3);
  scene.geoms.back().size = Eigen::Vector3d(0.02, 1.2, 1.0);
  auto full = [](const ImageU8& img) {
    int n = 0;
    for (size_t i = 0; i + 2 < img.data.size(); i += 3)
      n += img.data[i] == 255 && img.data[i + 1] == 255 && img.data[i + 2] == 255;
    return static_cast<double>(n) / (img.width * img.height);
  };
  const CameraImages ideal = ProfileCapture(scene, CameraSensorConfig(), 2);
  EXPECT_GT(full(ideal.rgb), 0.03);
  for (CameraProfile p : {CameraProfile::kRealsenseD435Rgb, CameraProfile::kBlackflySImx250}) {
    const CameraImages real = ProfileCapture(scene, CameraProfileConfig(p), 2);
    EXPECT_LT(full(real.rgb), 0.01) << CameraProfileName(p);
  }
}

TEST(CameraProfileTest, VignettingDarkensTheCornersByCos4) {
  // a uniform emissive wall filling the view, linear tone curve, no noise: corner / centre of
  // the developed linear values = cos^4 of the corner's field angle
  SceneDescription s = testing::BlackScene();
  const int wall = AddMaterial(&s, Eigen::Vector3f::Zero(), Eigen::Vector3f::Constant(1.0f));
  AddGeom(&s, GeomShape::kBox, {0.05, 50, 50}, {3, 0, 0}, wall);
  CameraSensorConfig cfg;
  cfg.optics.vignetting_exponent = 4;
  RenderSettings rs = ProfileRealtime(1);
  rs.auto_exposure = false;
  rs.tone_map = RenderSettings::ToneMap::kLinear;
  rs.ev100 = -std::log2(1.2 * 0.5);  // exposure H = 0.5: the wall at 0.5
  auto renderer = MakeRenderer(s, rs);
  const CameraSpec spec = ProfileSpec(160, 120);
  CameraImager imager(spec, cfg, rs, 0, s);
  CameraImages img;
  imager.Capture(renderer.get(), Snapshot(s, 0), nullptr, LookingAlongX({0, 0, 1}), nullptr,
                 Pose::Identity(), 0, &img);
  const CameraIntrinsics& k = spec.intrinsics;
  const double a = (0 - k.cx) / k.fx, b = (0 - k.cy) / k.fy;
  const double expected = std::pow(1 + a * a + b * b, -2.0);
  auto linear = [](uint8_t v) {  // sRGB decode
    const double c = v / 255.0;
    return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
  };
  const double corner = linear(img.rgb.at(0, 0)[1]), centre = linear(img.rgb.at(80, 60)[1]);
  EXPECT_NEAR(centre, 0.5, 0.01);
  EXPECT_NEAR(corner / centre, expected, 0.03);
}

TEST(CameraProfileTest, BadSettingsAreRefusedWithTheirKey) {
  CameraSensorConfig c = CameraProfileConfig(CameraProfile::kRealsenseD435Rgb);
  c.auto_exposure.max_gain = 0.5;
  try {
    ValidateCameraSensorOrThrow(c, "cameras[front]");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("cameras[front].auto_exposure.max_gain"),
              std::string::npos)
        << e.what();
  }
  c = CameraProfileConfig(CameraProfile::kRealsenseD435Rgb);
  c.noise.prnu = 2;
  EXPECT_THROW(ValidateCameraSensorOrThrow(c, "cameras[front]"), ConfigError);
}

}  // namespace
}  // namespace penumbra
