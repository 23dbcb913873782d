#include "penumbra/sensors/depth_noise.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "camera_sensor_test_util.h"
#include "penumbra/core/error.h"
#include "penumbra/core/thread_pool.h"
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

// luminance (cd/m^2) of a Lambertian surface of reflectance rho under illuminance E (lux).
double Luminance(double rho, double lux) { return rho * lux / M_PI; }
constexpr double kOfficeLux = 400;       // indoor office lighting
constexpr double kBrightLux = 5000;      // a room by a sunlit window
constexpr double kSunlightLux = 100000;  // direct sunlight

// a synthetic frame for ApplyDepthNoise: pinhole fx = fy = f, principal point at the centre; a
// fronto-parallel wall at z of reflectance rho lit by `lux` (ambient luminance image), clear air.
struct Frame {
  int W, H;
  double f;
  ImageF depth, normals, refl, ambient, trans;
  Frame(int w, int h, double focal, double z, double rho, double lux)
      : W(w),
        H(h),
        f(focal),
        depth(w, h, 1, static_cast<float>(z)),
        normals(w, h, 3),
        refl(w, h, 1, static_cast<float>(rho)),
        ambient(w, h, 1, static_cast<float>(Luminance(rho, lux))),
        trans(w, h, 1, 1.0f) {
    for (int v = 0; v < h; ++v)
      for (int u = 0; u < w; ++u) normals.at(u, v)[2] = -1.0f;
  }
  DepthNoiseInputs Inputs() const {
    DepthNoiseInputs in;
    in.normal_O = &normals;
    in.reflectance = &refl;
    in.ambient_cd_m2 = &ambient;
    in.transmittance = &trans;
    in.fx = in.fy = f;
    in.cx = 0.5 * (W - 1);
    in.cy = 0.5 * (H - 1);
    return in;
  }
  // a printed checkerboard of `cell` px (reflectance 0.15 / 0.8) on the rectangle given
  void Checker(int u0, int u1, int v0, int v1, int cell, double lux) {
    for (int v = v0; v < v1; ++v)
      for (int u = u0; u < u1; ++u) {
        const double rho = ((u / cell + v / cell) % 2) ? 0.8 : 0.15;
        *refl.at(u, v) = static_cast<float>(rho);
        *ambient.at(u, v) = static_cast<float>(Luminance(rho, lux));
      }
  }
};

DepthNoiseModel Preset(const std::string& name) {
  DepthNoiseConfig cfg;
  cfg.preset = name;
  return DepthNoisePreset(cfg, "d");
}

ImageF Apply(const Frame& fr, const DepthNoiseModel& m, uint64_t key = 11,
             ThreadPool* pool = nullptr) {
  ImageF out;
  ApplyDepthNoise(fr.depth, fr.Inputs(), m, key, &out, pool);
  return out;
}

// fraction of valid pixels in the central `roi` fraction of the image (the datasheet's 80 %
// ROI), right of the left invalid band.
double FillRate(const ImageF& out, double roi, int band_px = 0) {
  const int W = out.width, H = out.height;
  const int u0 = std::max(band_px, static_cast<int>(W * (1 - roi) / 2)),
            u1 = static_cast<int>(W * (1 + roi) / 2);
  const int v0 = static_cast<int>(H * (1 - roi) / 2), v1 = static_cast<int>(H * (1 + roi) / 2);
  int valid = 0, n = 0;
  for (int v = v0; v < v1; ++v)
    for (int u = u0; u < u1; ++u, ++n) valid += *out.at(u, v) > 0;
  return static_cast<double>(valid) / std::max(1, n);
}

// the holes (0) of `out` in columns [u0, W): fraction, and the share of hole pixels that lie in
// 4-connected components smaller than `small_px`.
struct Holes {
  double fraction = 0, small_share = 0;
  int components = 0;
};
Holes HoleComponents(const ImageF& out, int u0, int small_px) {
  cv::Mat mask(out.height, out.width - u0, CV_8U);
  int holes = 0;
  for (int v = 0; v < out.height; ++v)
    for (int u = u0; u < out.width; ++u) {
      const bool hole = !(*out.at(u, v) > 0);
      mask.at<uint8_t>(v, u - u0) = hole ? 255 : 0;
      holes += hole;
    }
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 4);
  int small = 0;
  for (int c = 1; c < n; ++c) {
    const int area = stats.at<int>(c, cv::CC_STAT_AREA);
    if (area < small_px) small += area;
  }
  Holes h;
  h.fraction = static_cast<double>(holes) / mask.total();
  h.small_share = holes ? static_cast<double>(small) / holes : 0.0;
  h.components = n - 1;
  return h;
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
    // every pixel returns, but for the stereo model's left invalid band (fx b / z columns)
    const DepthNoiseModel m = DepthNoisePreset(DepthNoiseConfig{c.preset, {}, {}}, "d");
    const double fx = CameraIntrinsics::FromFovy(160, 120, 40).fx;
    const int band = static_cast<int>(std::ceil(m.InvalidBandPx(c.z, fx)));
    EXPECT_NEAR(st.valid, (160 - band) * 120, 2 * 120) << c.preset;
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

// the stereo matcher loses a textureless wall in contiguous regions, not salt and pepper.
// criterion: with 4-connectivity, at least 90 % of the hole pixels lie in components of 10 px
// or more, while independent per-pixel holes of the same fraction (up to 35 %, below
// percolation) leave most hole pixels in components under 10 px.
TEST(DepthNoiseTest, StereoHolesOnTexturelessWallAreConnected) {
  const DepthNoiseModel m = Preset("realsense_d435");
  for (const double z : {3.3, 3.5, 3.7, 4.0}) {
    const Frame fr(320, 240, 300, z, 0.8, kBrightLux);
    const ImageF out = Apply(fr, m);
    const int band = static_cast<int>(std::ceil(m.InvalidBandPx(z, fr.f))) + 1;
    const Holes h = HoleComponents(out, band, 10);
    std::printf("textureless wall %.1f m: holes %.1f %%, %d components, %.1f %% in small ones\n", z,
                100 * h.fraction, h.components, 100 * h.small_share);
    EXPECT_GT(h.fraction, 0.05) << z;  // the working range ends around here
    EXPECT_LT(h.fraction, 0.95) << z;
    EXPECT_LT(h.small_share, 0.10) << z;
    if (h.fraction > 0.35) continue;
    // the same fraction of independent holes fails the criterion
    ImageF salt(320, 240, 1, 1.0f);
    Rng rng(5);
    for (float& d : salt.data)
      if (rng.UniformD() < h.fraction) d = 0.0f;
    EXPECT_GT(HoleComponents(salt, band, 10).small_share, 0.5) << z;
  }
}

TEST(DepthNoiseTest, LeftInvalidBandIsFxBaselineOverZ) {
  const DepthNoiseModel m = Preset("realsense_d435");
  for (const double z : {0.5, 1.0, 2.0, 4.0}) {
    Frame fr(320, 240, 300, z, 0.8, kOfficeLux);
    fr.Checker(0, 320, 0, 240, 4, kOfficeLux);  // textured: only the band is missing
    const ImageF out = Apply(fr, m);
    const double band = fr.f * m.stereo_baseline_m / z;
    EXPECT_DOUBLE_EQ(m.InvalidBandPx(z, fr.f), band);
    // the first valid column of each row, averaged
    double first = 0;
    for (int v = 0; v < 240; ++v) {
      int u = 0;
      while (u < 320 && !(*out.at(u, v) > 0)) ++u;
      first += u / 240.0;
    }
    std::printf("band at %.1f m: first valid column %.2f, fx b / z = %.2f\n", z, first, band);
    EXPECT_NEAR(first, std::ceil(band), 1.0) << z;
  }
}

TEST(DepthNoiseTest, OcclusionShadowLeftOfForegroundEdge) {
  const DepthNoiseModel m = Preset("realsense_d435");
  Frame fr(320, 240, 300, 3.0, 0.8, kOfficeLux);
  fr.Checker(0, 320, 0, 240, 4, kOfficeLux);
  for (int v = 0; v < 240; ++v)
    for (int u = 150; u < 220; ++u) *fr.depth.at(u, v) = 1.0f;  // a box at 1 m
  const ImageF out = Apply(fr, m);
  // disparities 300 * 0.05 / 1 = 15 and / 3 = 5: columns [140, 150) are seen by one imager only
  int shadow = 0, lit = 0;
  for (int v = 0; v < 240; ++v) {
    for (int u = 141; u < 149; ++u) shadow += !(*out.at(u, v) > 0);
    for (int u = 120; u < 138; ++u) lit += *out.at(u, v) > 0;
  }
  EXPECT_GT(shadow, 0.95 * 8 * 240);
  EXPECT_GT(lit, 0.95 * 18 * 240);
  // nothing is lost right of the box (the right imager sees that side)
  int right = 0;
  for (int v = 0; v < 240; ++v)
    for (int u = 222; u < 300; ++u) right += *out.at(u, v) > 0;
  EXPECT_GT(right, 0.95 * 78 * 240);
}

TEST(DepthNoiseTest, TexturedWallFillsMoreThanTexturelessWall) {
  const DepthNoiseModel m = Preset("realsense_d435");
  for (const double z : {4.0, 6.0}) {
    const Frame plain(320, 240, 300, z, 0.8, kBrightLux);
    Frame textured(320, 240, 300, z, 0.8, kBrightLux);
    textured.Checker(0, 320, 0, 240, 6, kBrightLux);
    const int band = static_cast<int>(std::ceil(m.InvalidBandPx(z, 300))) + 2;
    const double fill_plain = FillRate(Apply(plain, m), 0.8, band),
                 fill_textured = FillRate(Apply(textured, m), 0.8, band);
    std::printf("wall at %.1f m: fill textureless %.3f, textured %.3f\n", z, fill_plain,
                fill_textured);
    EXPECT_GT(fill_textured, 0.99) << z;
    EXPECT_LT(fill_plain, fill_textured - 0.2) << z;
  }
}

// published characterisation of the D435 (see depth_noise.h): the datasheet's active-stereo
// depth quality on a textureless white wall (80 % ROI: fill rate >= 99 %, RMS error <= 2 % at
// 2 m), the Tuning paper's RMS error z^2 subpixel / (f b) (within 10 %), and the Projectors
// paper's sunlight: passive texture keeps working, the projector's dots wash out. fill falls
// with distance; in a bright room a textureless wall breaks up within the 10 m range.
TEST(DepthNoiseTest, D435MatchesPublishedCharacterisation) {
  const DepthNoiseModel m = Preset("realsense_d435");
  const double f = 425;  // 848 x 480, ~87 deg HFOV
  std::vector<double> fills;
  for (const double z : {0.5, 1.0, 2.0, 3.0, 4.0, 5.0}) {
    const Frame fr(424, 240, f / 2, z, 0.8, kOfficeLux);  // half resolution: f / 2
    const ImageF out = Apply(fr, m);
    const int band = static_cast<int>(std::ceil(m.InvalidBandPx(z, fr.f))) + 2;
    const double fill = FillRate(out, 0.8, band);
    fills.push_back(fill);
    double s = 0, s2 = 0;
    int n = 0;
    for (float d : out.data) {
      if (!(d > 0)) continue;
      s += d;
      s2 += static_cast<double>(d) * d;
      ++n;
    }
    const double mean = s / n, rms = std::sqrt(std::max(0.0, s2 / n - mean * mean));
    const double published = z * z * 0.08 / (fr.f * 0.05);
    std::printf("D435 white wall %.1f m: fill %.4f, RMS %.2f mm (published %.2f mm)\n", z, fill,
                1e3 * rms, 1e3 * published);
    if (z <= 3.0) {
      EXPECT_NEAR(rms, published, 0.10 * published) << z;
    }
    if (z <= 2.0) {
      EXPECT_GE(fill, 0.99) << z;
    }
    if (z == 2.0) {
      EXPECT_LE(rms / z, 0.02);
    }
    if (z == 3.0) {
      EXPECT_GE(fill, 0.90);
    }
  }
  for (size_t i = 1; i < fills.size(); ++i) EXPECT_LE(fills[i], fills[i - 1] + 0.005);
  std::vector<double> bright;
  for (const double z : {1.0, 2.0, 3.0, 4.0, 5.0, 6.0}) {
    const Frame fr(424, 240, f / 2, z, 0.8, kBrightLux);
    bright.push_back(FillRate(Apply(fr, m), 0.8, 30));
    std::printf("D435 white wall %.1f m in a bright room: fill %.4f\n", z, bright.back());
  }
  EXPECT_GE(bright[1], 0.99);
  EXPECT_LT(bright.back(), 0.5);
  for (size_t i = 1; i < bright.size(); ++i) EXPECT_LE(bright[i], bright[i - 1] + 0.005);
  // sunlight: a textureless wall at 1.5 m is lost, a textured one is not
  const Frame sun(424, 240, f / 2, 1.5, 0.8, kSunlightLux);
  Frame sun_textured(424, 240, f / 2, 1.5, 0.8, kSunlightLux);
  sun_textured.Checker(0, 424, 0, 240, 6, kSunlightLux);
  EXPECT_LT(FillRate(Apply(sun, m), 0.8, 30), 0.05);
  EXPECT_GT(FillRate(Apply(sun_textured, m), 0.8, 30), 0.99);
  // darkness: the projector alone still textures the wall at 3 m
  EXPECT_GT(FillRate(Apply(Frame(424, 240, f / 2, 3.0, 0.8, 0.0), m), 0.8, 30), 0.99);
}

// structured light (kinect_v1): its own pattern behind a band-pass filter; a textureless wall
// fills in office light to its 4 m range, sunlight (in band) washes the pattern out and the
// scene's own texture does not help (it fails outdoors); no left invalid band.
TEST(DepthNoiseTest, KinectV1SeesItsPatternIndoorsNotInSunlight) {
  const DepthNoiseModel m = Preset("kinect_v1");
  EXPECT_EQ(m.InvalidBandPx(2.0, 300), 0.0);
  for (const double z : {1.0, 2.0, 3.5}) {
    const ImageF out = Apply(Frame(320, 240, 300, z, 0.8, kOfficeLux), m);
    EXPECT_GE(FillRate(out, 1.0), 0.99) << z;
  }
  EXPECT_LT(FillRate(Apply(Frame(320, 240, 300, 1.5, 0.8, kSunlightLux), m), 0.8), 0.05);
  Frame textured(320, 240, 300, 1.5, 0.8, kSunlightLux);
  textured.Checker(0, 320, 0, 240, 6, kSunlightLux);
  EXPECT_LT(FillRate(Apply(textured, m), 0.8), 0.05);
}

TEST(DepthNoiseTest, DarkAndSpecularSurfacesDropReturns) {
  // stereo: a dark patch and a mirror in a white textureless wall at 2 m in a bright room
  Frame fr(320, 240, 300, 2.0, 0.8, kBrightLux);
  for (int v = 60; v < 180; ++v)
    for (int u = 40; u < 120; ++u) {
      *fr.refl.at(u, v) = 0.02f;
      *fr.ambient.at(u, v) = static_cast<float>(Luminance(0.02, kBrightLux));
    }
  for (int v = 60; v < 180; ++v)
    for (int u = 200; u < 280; ++u) *fr.refl.at(u, v) = -1.0f;
  const ImageF out = Apply(fr, Preset("realsense_d435"));
  int dark = 0, mirror = 0, white = 0;
  for (int v = 70; v < 170; ++v) {
    for (int u = 50; u < 110; ++u) dark += *out.at(u, v) > 0;
    for (int u = 203; u < 277; ++u) mirror += *out.at(u, v) > 0;
    for (int u = 140; u < 180; ++u) white += *out.at(u, v) > 0;
  }
  EXPECT_LT(dark, 0.05 * 100 * 60);
  EXPECT_EQ(mirror, 0);
  EXPECT_GT(white, 0.99 * 100 * 40);
  // time of flight: per pixel, below min_reflectance or specular
  ImageF depth(3, 1, 1, 1.0f), refl(3, 1, 1);
  *refl.at(0, 0) = 0.01f;  // dark
  *refl.at(1, 0) = -1.0f;  // specular
  *refl.at(2, 0) = 0.5f;
  DepthNoiseInputs in;
  in.reflectance = &refl;
  ImageF tof;
  ApplyDepthNoise(depth, in, Preset("kinect_v2"), 1, &tof);
  EXPECT_EQ(*tof.at(0, 0), 0.0f);
  EXPECT_EQ(*tof.at(1, 0), 0.0f);
  EXPECT_GT(*tof.at(2, 0), 0.9f);
}

TEST(DepthNoiseTest, FogDropsReturnsWithRoundTripTransmittance) {
  // homogeneous fog sigma = 0.2 / m; wall at 2 m: T = exp(-0.4)
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
  // time of flight: each pixel keeps its return with probability T^2 = exp(-0.8)
  DepthNoiseInputs in;
  in.transmittance = &t;
  in.fx = k.fx;
  ImageF out;
  ApplyDepthNoise(depth, in, Preset("kinect_v2"), 9, &out);
  int kept = 0;
  for (float d : out.data) kept += d > 0;
  const double p = std::exp(-0.8);
  EXPECT_NEAR(kept / 1e4, p, 4 * std::sqrt(p * (1 - p) / 1e4));
  // thick smoke: below the threshold every return is lost, whatever the sensor
  fog.sigma_t_per_m = Eigen::Vector3f(2, 2, 2);
  fx.homogeneous_media = {fog};
  const ImageF t2 = DepthTransmittance(depth, cam, fx, 1);
  in.transmittance = &t2;
  for (const char* preset : {"kinect_v2", "realsense_d435", "kinect_v1"}) {
    ApplyDepthNoise(depth, in, Preset(preset), 9, &out);
    for (float d : out.data) EXPECT_EQ(d, 0.0f) << preset;
  }
}

// stereo in fog: the projector's dots fade with T^2 and the backscatter veil adds noise, so the
// fill rate falls, and the holes are contiguous (the criterion of the textureless-wall test).
TEST(DepthNoiseTest, StereoFogLowersFillWithContiguousHoles) {
  const DepthNoiseModel m = Preset("realsense_d435");
  const double z = 2.5;
  Frame fr(320, 240, 300, z, 0.8, kOfficeLux);
  const int band = static_cast<int>(std::ceil(m.InvalidBandPx(z, fr.f))) + 2;
  const double clear = FillRate(Apply(fr, m), 1.0, band);
  double last = clear;
  for (const double sigma : {0.1, 0.2, 0.3, 0.4}) {
    Frame foggy = fr;
    const float t = static_cast<float>(std::exp(-sigma * z));
    std::fill(foggy.trans.data.begin(), foggy.trans.data.end(), t);
    // what the imagers see of the wall through the fog, plus the ambient light it scatters
    for (float& l : foggy.ambient.data) l = l * t + (1 - t) * Luminance(0.8, kOfficeLux);
    const ImageF out = Apply(foggy, m);
    const double fill = FillRate(out, 1.0, band);
    const Holes h = HoleComponents(out, band, 10);
    std::printf("fog sigma %.2f / m at %.1f m: fill %.3f (clear %.3f), %.1f %% in small holes\n",
                sigma, z, fill, clear, 100 * h.small_share);
    EXPECT_LT(fill, last + 1e-9);
    if (h.fraction > 0.05) {
      EXPECT_LT(h.small_share, 0.10) << sigma;
    }
    last = fill;
  }
  EXPECT_LT(last, 0.5 * clear);
}

// time of flight: a pixel on a depth edge mixes both returns into one between them; pixels
// away from edges read their own surface.
TEST(DepthNoiseTest, TofMixedPixelsOnlyAtDepthEdges) {
  DepthNoiseModel m = Preset("kinect_v2");
  m.lateral_sigma_px = 0;
  ImageF depth(60, 40, 1, 2.0f);
  for (int v = 0; v < 40; ++v)
    for (int u = 0; u < 30; ++u) *depth.at(u, v) = 1.0f;
  DepthNoiseInputs in;
  in.fx = in.fy = 400;  // the stereo model's axial noise at 2 m: 16 mm
  in.cx = 30;
  in.cy = 20;
  ImageF out;
  ApplyDepthNoise(depth, in, m, 4, &out);
  int mixed_at_edge = 0;
  for (int v = 0; v < 40; ++v) {
    for (int u = 0; u < 60; ++u) {
      const float d = *out.at(u, v);
      ASSERT_GT(d, 0.0f);
      const bool between = d > 1.05f && d < 1.95f;
      if (u == 29 || u == 30) {
        mixed_at_edge += between;
      } else {
        EXPECT_FALSE(between) << u << "," << v << ": " << d;
      }
    }
  }
  EXPECT_GE(mixed_at_edge, 40);  // the background side of every row floats toward the front
  // the stereo model has no mixed returns (it loses or keeps a pixel)
  ApplyDepthNoise(depth, in, Preset("realsense_d435"), 4, &out);
  for (float d : out.data) EXPECT_FALSE(d > 1.05f && d < 1.95f);
}

// time of flight: in a concave corner light bounces from one wall to the other before it
// returns, so depth reads long near the corner; a flat wall and a convex ridge have none.
TEST(DepthNoiseTest, TofMultipathBiasInConcaveCorner) {
  DepthNoiseModel m = Preset("kinect_v2");
  m.lateral_sigma_px = 0;
  const int W = 160, H = 120;
  const double f = 120, c = 2.0;
  // bias of the corner region (|x| < 0.15) and of the outer region (|x| > 0.45), averaged
  auto measure = [&](int shape, double* near, double* far) {
    ImageF depth(W, H, 1), normals(W, H, 3);
    for (int v = 0; v < H; ++v) {
      for (int u = 0; u < W; ++u) {
        const double x = (u - 0.5 * (W - 1)) / f, s = x < 0 ? -1.0 : 1.0;
        float* n = normals.at(u, v);
        if (shape == 0) {  // flat wall
          *depth.at(u, v) = static_cast<float>(c);
          n[2] = -1;
        } else if (shape == 1) {  // concave: walls z = c - |x| z meet at (0, c), facing each other
          *depth.at(u, v) = static_cast<float>(c / (1 + std::abs(x)));
          n[0] = static_cast<float>(-s / std::sqrt(2.0));
          n[2] = static_cast<float>(-1 / std::sqrt(2.0));
        } else {  // convex ridge z = c + |x| z (c / (1 - |x|)), facing away from each other
          *depth.at(u, v) = static_cast<float>(c / (1 - std::abs(x)));
          n[0] = static_cast<float>(s / std::sqrt(2.0));
          n[2] = static_cast<float>(-1 / std::sqrt(2.0));
        }
      }
    }
    DepthNoiseInputs in;
    in.normal_O = &normals;
    in.fx = in.fy = f;
    in.cx = 0.5 * (W - 1);
    in.cy = 0.5 * (H - 1);
    ImageF out;
    ApplyDepthNoise(depth, in, m, 6, &out);
    double sn = 0, sf = 0;
    int nn = 0, nf = 0;
    for (int v = 0; v < H; ++v)
      for (int u = 0; u < W; ++u) {
        const double x = std::abs((u - 0.5 * (W - 1)) / f);
        const double e = *out.at(u, v) - *depth.at(u, v);
        if (!(*out.at(u, v) > 0) || (x > 0.01 && x < 0.02)) continue;
        if (x < 0.15) sn += e, ++nn;
        if (x > 0.45) sf += e, ++nf;
      }
    *near = sn / nn;
    *far = sf / nf;
  };
  double flat_n, flat_f, cc_n, cc_f, cv_n, cv_f;
  measure(0, &flat_n, &flat_f);
  measure(1, &cc_n, &cc_f);
  measure(2, &cv_n, &cv_f);
  std::printf("multipath bias: flat %.2f / %.2f mm, concave %.2f / %.2f mm, convex %.2f / %.2f\n",
              1e3 * flat_n, 1e3 * flat_f, 1e3 * cc_n, 1e3 * cc_f, 1e3 * cv_n, 1e3 * cv_f);
  for (const double b : {flat_n, flat_f, cv_n, cv_f}) EXPECT_NEAR(b, 0, 2e-3);
  EXPECT_GT(cc_n, 0.01);  // centimetres long where the walls see each other
  EXPECT_GT(cc_f, 0.01);
  m.multipath = false;  // without multipath the corner reads true
  measure(1, &cc_n, &cc_f);
  EXPECT_NEAR(cc_n, 0, 2e-3);
}

TEST(DepthNoiseTest, SameOutputForEveryThreadCountAndInputUntouched) {
  Frame fr(200, 150, 180, 3.0, 0.8, kOfficeLux);
  fr.Checker(100, 200, 0, 150, 5, kOfficeLux);
  for (int v = 0; v < 150; ++v)
    for (int u = 60; u < 90; ++u) {
      *fr.depth.at(u, v) = 1.2f;
      *fr.trans.at(u, v) = 0.7f;
      float* n = fr.normals.at(u, v);
      n[0] = 0.3f;
      n[2] = -0.95f;
    }
  const ImageF depth_before = fr.depth;
  for (const char* preset : {"realsense_d435", "kinect_v1", "kinect_v2"}) {
    const DepthNoiseModel m = Preset(preset);
    const ImageF serial = Apply(fr, m, 21);
    for (const int threads : {1, 2, 5}) {
      ThreadPool pool(threads);
      const ImageF par = Apply(fr, m, 21, &pool);
      EXPECT_EQ(par.data, serial.data) << preset << " with " << threads << " threads";
    }
    EXPECT_NE(Apply(fr, m, 22).data, serial.data) << preset;  // the key matters
  }
  EXPECT_EQ(fr.depth.data, depth_before.data);
}

TEST(DepthNoiseTest, MismatchedInputSizeIsAnError) {
  const ImageF depth(10, 10, 1, 1.0f), refl(5, 10, 1, 0.5f);
  DepthNoiseInputs in;
  in.reflectance = &refl;
  ImageF out;
  EXPECT_THROW(ApplyDepthNoise(depth, in, Preset("realsense_d435"), 1, &out), Error);
}

// a rendered room for the D435 model: a white textureless back wall at 4.2 m whose left part
// carries a printed checker poster, a grey box at 1.5 m, the light of a room by a sunlit
// window (a 5000 lux directional light from behind the camera). captured clear and in fog (sigma_t
// 0.12 / m). writes the picture of docs/sensors.md (rgb | depth clear | depth fog) when
// PENUMBRA_DOC_IMAGES names a folder:
//   PENUMBRA_DOC_IMAGES=docs build/sensors_tests --gtest_filter=DepthNoiseTest.RenderedRoom*
TEST(DepthNoiseTest, RenderedRoomTexturedFillsTexturelessBreaksFogLoses) {
  SceneDescription scene = BlackScene();
  const int white = AddMaterial(&scene, Eigen::Vector3f(0.8f, 0.8f, 0.8f));
  const int dark = AddMaterial(&scene, Eigen::Vector3f(0.08f, 0.08f, 0.08f));
  const int grey = AddMaterial(&scene, Eigen::Vector3f(0.5f, 0.45f, 0.4f));
  const double wall = 4.2;
  AddGeom(&scene, GeomShape::kBox, Eigen::Vector3d(0.01, 6, 6), Eigen::Vector3d(wall + 0.01, 0, 0),
          white);
  // poster: 0.1 m squares, world y in [0.4, 2.0] (image left), z in [-0.9, 0.9]
  for (int i = 0; i < 16; ++i)
    for (int j = 0; j < 18; ++j)
      if ((i + j) % 2)
        AddGeom(&scene, GeomShape::kBox, Eigen::Vector3d(0.005, 0.05, 0.05),
                Eigen::Vector3d(wall - 0.005, 0.45 + 0.1 * i, -0.85 + 0.1 * j), dark);
  AddGeom(&scene, GeomShape::kBox, Eigen::Vector3d(0.2, 0.25, 0.25),
          Eigen::Vector3d(1.5, -0.6, -0.2), grey);
  Light sun;
  sun.type = Light::Type::kDirectional;
  sun.direction_B = Eigen::Vector3d(1, 0, 0);
  sun.intensity = 5000;
  sun.cast_shadow = false;
  scene.lights.push_back(sun);
  RenderSettings rs;
  rs.tier = RenderSettings::Tier::kRealtime;
  auto renderer = MakeRenderer(scene, rs);
  CameraSpec spec;
  spec.name = "d435";
  spec.intrinsics = CameraIntrinsics::FromFovy(320, 240, 58);
  spec.outputs = CameraOutputs{ImageKind::kRgb, ImageKind::kDepth};
  CameraSensorConfig cfg;
  cfg.depth_noise.preset = "realsense_d435";
  CameraImager imager(spec, cfg, rs, 0, scene);
  CameraSensorConfig exact_cfg;
  CameraImager exact(spec, exact_cfg, rs, 0, scene);
  const WorldSnapshot snap = testing::Snapshot(scene, 0);
  const Pose X_WO = testing::LookingAlongX(Eigen::Vector3d::Zero());
  EffectsFrame fog;
  HomogeneousMedium m;
  m.sigma_t_per_m = Eigen::Vector3f(0.12f, 0.12f, 0.12f);
  m.albedo = Eigen::Vector3f(0.9f, 0.9f, 0.9f);
  fog.homogeneous_media.push_back(m);
  CameraImages clear, foggy, truth;
  imager.Capture(renderer.get(), snap, nullptr, X_WO, nullptr, Pose::Identity(), 0, &clear);
  imager.Capture(renderer.get(), snap, &fog, X_WO, nullptr, Pose::Identity(), 1, &foggy);
  exact.Capture(renderer.get(), snap, nullptr, X_WO, nullptr, Pose::Identity(), 0, &truth);
  // the ground truth stays exact
  EXPECT_EQ(clear.truth.depth_m.data, truth.depth_m.data);
  EXPECT_EQ(truth.depth_m.data, truth.truth.depth_m.data);
  // fill of the poster (image left of centre) and of the plain wall right of the box
  const CameraIntrinsics& k = spec.intrinsics;
  auto fill = [&](const ImageF& d, double y0, double y1) {
    int valid = 0, n = 0;
    for (int v = 0; v < k.height; ++v)
      for (int u = 0; u < k.width; ++u) {
        const double y = -(u - k.cx) / k.fx * wall, z = -(v - k.cy) / k.fy * wall;
        if (y < y0 || y > y1 || std::abs(z) > 0.8 ||
            std::abs(truth.depth_m.at(u, v)[0] - wall) > 0.05)
          continue;
        ++n;
        valid += d.at(u, v)[0] > 0;
      }
    return static_cast<double>(valid) / std::max(1, n);
  };
  const double poster = fill(clear.depth_m, 0.5, 1.9), plain = fill(clear.depth_m, -2.0, -1.2);
  const double poster_fog = fill(foggy.depth_m, 0.5, 1.9);
  std::printf("rendered room: fill poster %.3f, plain wall %.3f, poster in fog %.3f\n", poster,
              plain, poster_fog);
  EXPECT_GT(poster, 0.98);
  EXPECT_LT(plain, poster - 0.2);
  EXPECT_LT(poster_fog, poster - 0.2);
  if (const char* dir = std::getenv("PENUMBRA_DOC_IMAGES")) {
    const int W = k.width, H = k.height;
    cv::Mat panel(H, 3 * W, CV_8UC3);
    for (int v = 0; v < H; ++v)
      for (int u = 0; u < W; ++u) {
        const uint8_t* c = clear.rgb.at(u, v);
        panel.at<cv::Vec3b>(v, u) = cv::Vec3b(c[2], c[1], c[0]);
      }
    for (int p = 0; p < 2; ++p) {
      const ImageF& d = p == 0 ? clear.depth_m : foggy.depth_m;
      cv::Mat g(H, W, CV_8U), colour;
      for (int v = 0; v < H; ++v)
        for (int u = 0; u < W; ++u)
          g.at<uint8_t>(v, u) =
              static_cast<uint8_t>(std::clamp(d.at(u, v)[0] / 5.0 * 255.0, 0.0, 255.0));
      cv::applyColorMap(g, colour, cv::COLORMAP_TURBO);
      for (int v = 0; v < H; ++v)
        for (int u = 0; u < W; ++u)
          panel.at<cv::Vec3b>(v, (p + 1) * W + u) =
              d.at(u, v)[0] > 0 ? colour.at<cv::Vec3b>(v, u) : cv::Vec3b(0, 0, 0);
    }
    const std::string path = (std::filesystem::path(dir) / "depth_d435.png").string();
    ASSERT_TRUE(cv::imwrite(path, panel)) << path;
    std::printf("wrote %s\n", path.c_str());
  }
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
