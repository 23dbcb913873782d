#include "penumbra/sensors/camera_imager.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <tuple>
#include <vector>

#include "camera_sensor_test_util.h"
#include "penumbra/core/error.h"
#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/render/camera/camera_distortion.h"
#include "penumbra/render/renderer.h"
#include "penumbra/sensors/camera_lens_droplets.h"

namespace penumbra {
namespace {

using testing::AddGeom;
using testing::AddMaterial;
using testing::BlackScene;
using testing::LookingAlongX;
using testing::Snapshot;

constexpr double kZ = 2.0;  // distance of the target plane

// an emissive vertical bar (world z) of width `width_m` at distance kZ in front of a camera at
// the origin looking along +x; black elsewhere. image x = world -y.
SceneDescription Bar(double width_m, double centre_y = 0) {
  SceneDescription s = BlackScene();
  const int m = AddMaterial(&s, Eigen::Vector3f::Zero(), Eigen::Vector3f::Ones());
  AddGeom(&s, GeomShape::kBox, Eigen::Vector3d(0.01, width_m / 2, 5),
          Eigen::Vector3d(kZ + 0.01, centre_y, 0), m);
  return s;
}

RenderSettings Realtime() {
  RenderSettings rs;
  rs.tier = RenderSettings::Tier::kRealtime;
  rs.auto_exposure = false;
  rs.ev100 = -std::log2(1.2);  // exposure H = 1: exposed value = radiance
  return rs;
}

CameraSpec Spec(int w, int h, double f) {
  CameraSpec spec;
  spec.name = "cam";
  spec.intrinsics.width = w;
  spec.intrinsics.height = h;
  spec.intrinsics.fx = spec.intrinsics.fy = f;
  spec.intrinsics.cx = 0.5 * (w - 1);
  spec.intrinsics.cy = 0.5 * (h - 1);
  spec.outputs = CameraOutputs{ImageKind::kRgb};
  return spec;
}

// centroid (px) and number of lit columns of row v of the averaged radiance.
std::pair<double, int> RowProfile(const ImageF& radiance, int v) {
  double s = 0, sw = 0;
  int lit = 0;
  for (int u = 0; u < radiance.width; ++u) {
    const double w = radiance.at(u, v)[1];
    s += w * u;
    sw += w;
    lit += w > 1e-6;
  }
  return {s / sw, lit};
}

TEST(CameraImagerTest, MotionBlurSmearsByVelocityTimesExposure) {
  // camera moves along its optical x (world -y) at 2 m/s for T = 40 ms, f = 400 px, bar at 2 m:
  // the bar smears over |v| T f / z = 16 px.
  const double speed = 2.0, T = 0.04, f = 400;
  const double expected_px = speed * T * f / kZ;
  const SceneDescription scene = Bar(2.0 * kZ / f);  // 2 px wide
  auto renderer = MakeRenderer(scene, Realtime());
  CameraSensorConfig cfg;
  cfg.exposure_time_sec = T;
  cfg.motion_blur_samples = 64;
  CameraImager blurred(Spec(160, 40, f), cfg, Realtime(), 0, scene);
  cfg.motion_blur_samples = 1;
  CameraImager sharp(Spec(160, 40, f), cfg, Realtime(), 0, scene);
  const WorldSnapshot a = Snapshot(scene, 0), b = Snapshot(scene, T);
  const Pose X0 = LookingAlongX(Eigen::Vector3d::Zero());
  const Pose X1 = LookingAlongX(Eigen::Vector3d(0, -speed * T, 0));  // optical +x = world -y
  CameraImages im_blur, im_still;
  blurred.Capture(renderer.get(), a, nullptr, X0, &b, X1, 0, &im_blur);
  sharp.Capture(renderer.get(), a, nullptr, X0, nullptr, X0, 0, &im_still);
  ASSERT_FALSE(im_blur.radiance.empty());
  const auto [c_still, lit_still] = RowProfile(im_still.radiance, 20);
  const auto [c_blur, lit_blur] = RowProfile(im_blur.radiance, 20);
  // scene moves left (camera moves right): centroid shifts by half the smear
  const double smear_from_centroid = 2 * (c_still - c_blur);
  const int smear_from_extent = lit_blur - lit_still;
  std::printf("expected smear %.2f px; from centroid %.3f px, from lit extent %d px\n", expected_px,
              smear_from_centroid, smear_from_extent);
  EXPECT_NEAR(smear_from_centroid, expected_px, 1.0);
  EXPECT_NEAR(smear_from_extent, expected_px, 1.0 + 1.0);
  // rgb of the blurred frame is the developed average: a lit pixel at the far end of the smear
  const int far_u = static_cast<int>(std::lround(c_still - expected_px + 1));
  EXPECT_GT(im_blur.rgb.at(far_u, 20)[1], 0);
  EXPECT_EQ(im_still.rgb.at(far_u, 20)[1], 0);
}

TEST(CameraImagerTest, MovingBodiesBlurToo) {
  // a static camera; the bar (on its own body) moves 2 m/s along world -y during T = 40 ms:
  // in the image it moves right by v T f / z = 16 px, so the blurred centroid shifts by 8 px
  const double speed = 2.0, T = 0.04, f = 400;
  SceneDescription scene = Bar(2.0 * kZ / f);
  scene.bodies.push_back({"bar", 0, false});
  scene.geoms[0].body = 1;
  auto renderer = MakeRenderer(scene, Realtime());
  CameraSensorConfig cfg;
  cfg.exposure_time_sec = T;
  cfg.motion_blur_samples = 64;
  CameraImager imager(Spec(160, 40, f), cfg, Realtime(), 0, scene);
  WorldSnapshot a = Snapshot(scene, 0), b = Snapshot(scene, T);
  b.X_WB[1].translation() = Eigen::Vector3d(0, -speed * T, 0);
  const Pose X = LookingAlongX(Eigen::Vector3d::Zero());
  CameraImages blurred, still;
  imager.Capture(renderer.get(), a, nullptr, X, &b, X, 0, &blurred);
  imager.Capture(renderer.get(), a, nullptr, X, nullptr, X, 1, &still);
  const double shift =
      RowProfile(blurred.radiance, 20).first - RowProfile(still.radiance, 20).first;
  std::printf("moving body: smear from centroid %.3f px, expected %.3f px\n", 2 * shift,
              speed * T * f / kZ);
  EXPECT_NEAR(2 * shift, speed * T * f / kZ, 1.0);
}

TEST(CameraImagerTest, RollingShutterSkewsAVerticalEdge) {
  // global exposure 0, line time 100 us, camera moving 2 m/s along optical x, f = 400 px, 2 m:
  // each row shifts by v l f / z = 2 * 1e-4 * 400 / 2 = 0.04 px, 4.76 px over 120 rows.
  const double speed = 2.0, line = 1e-4, f = 400;
  const int H = 120;
  const double per_row = speed * line * f / kZ;
  // a wide bar right of the image centre: its left edge (world y = -0.1) is a vertical edge
  const SceneDescription scene = Bar(0.5, -0.35);
  auto renderer = MakeRenderer(scene, Realtime());
  CameraSensorConfig cfg;
  cfg.exposure_time_sec = 0;
  cfg.rolling_shutter_line_time_sec = line;
  CameraImager imager(Spec(160, H, f), cfg, Realtime(), 0, scene);
  const double span = FrameSpanSec(cfg, H);
  EXPECT_NEAR(span, (H - 1) * line, 1e-15);
  const WorldSnapshot a = Snapshot(scene, 0), b = Snapshot(scene, span);
  const Pose X0 = LookingAlongX(Eigen::Vector3d::Zero());
  const Pose X1 = LookingAlongX(Eigen::Vector3d(0, -speed * span, 0));
  CameraImages im;
  imager.Capture(renderer.get(), a, nullptr, X0, &b, X1, 0, &im);
  // left edge column of the lit bar per row; least-squares slope over rows
  double sv = 0, su = 0, svv = 0, svu = 0;
  for (int v = 0; v < H; ++v) {
    int u = 0;
    while (u < 160 && im.truth.radiance.at(u, v)[1] < 0.5f) ++u;
    sv += v;
    su += u;
    svv += v * v;
    svu += v * u;
  }
  const double slope = (H * svu - sv * su) / (H * svv - sv * sv);
  std::printf(
      "rolling shutter: expected %.4f px/row, measured %.4f px/row (total %.2f vs %.2f px)\n",
      -per_row, slope, slope * (H - 1), -per_row * (H - 1));
  EXPECT_NEAR(slope * (H - 1), -per_row * (H - 1), 1.0);
}

TEST(CameraImagerTest, AutoExposureAdaptsWithTimeConstant) {
  // dim scene then a 16x brighter one: the metered EV jumps by 4; the used EV moves
  // 1 - exp(-dt / tau) of the way
  SceneDescription dim = BlackScene(), bright = BlackScene();
  dim.sky.radiance = Eigen::Vector3f::Constant(10.0f);
  bright.sky.radiance = Eigen::Vector3f::Constant(160.0f);
  RenderSettings rs = Realtime();
  rs.auto_exposure = true;
  auto r_dim = MakeRenderer(dim, rs);
  auto r_bright = MakeRenderer(bright, rs);
  CameraSensorConfig cfg;
  cfg.auto_exposure_time_constant_sec = 0.5;
  CameraImager imager(Spec(32, 24, 30), cfg, rs, 0, dim);
  const Pose X = LookingAlongX(Eigen::Vector3d::Zero());
  CameraImages f0, f1, f2;
  imager.Capture(r_dim.get(), Snapshot(dim, 0.0), nullptr, X, nullptr, X, 0, &f0);
  imager.Capture(r_bright.get(), Snapshot(bright, 0.1), nullptr, X, nullptr, X, 1, &f1);
  imager.Capture(r_bright.get(), Snapshot(bright, 0.6), nullptr, X, nullptr, X, 2, &f2);
  const double ev_dim = std::log2(10.0 / (0.18 * 1.2)), ev_bright = ev_dim + 4;
  EXPECT_NEAR(f0.ev100, ev_dim, 1e-4);
  const double e1 = ev_bright + (ev_dim - ev_bright) * std::exp(-0.1 / 0.5);
  EXPECT_NEAR(f1.ev100, e1, 1e-4);
  EXPECT_NEAR(f2.ev100, ev_bright + (e1 - ev_bright) * std::exp(-0.5 / 0.5), 1e-4);
}

// a real renderer that, as CudaRenderer does, leaves the radiance out when the view does not
// want it (CameraView::want_radiance), and records what each Render was asked for.
class RadianceOnRequest : public Renderer {
 public:
  explicit RadianceOnRequest(std::unique_ptr<Renderer> inner) : inner_(std::move(inner)) {}
  void Render(const WorldSnapshot& snapshot, const EffectsFrame* effects, const CameraView& view,
              RenderedFrame* out) override {
    inner_->Render(snapshot, effects, view, out);
    asked.push_back(view.want_radiance);
    if (!view.want_radiance) out->radiance = ImageF();
  }
  std::vector<bool> asked;  // want_radiance of every Render, in call order

 private:
  std::unique_ptr<Renderer> inner_;
};

TEST(CameraImagerTest, WithoutKeepRadianceTheRadianceIsAskedForOnlyWhenNeeded) {
  const SceneDescription scene = Bar(0.1);
  const Pose X = LookingAlongX(Eigen::Vector3d::Zero());
  const WorldSnapshot snap = Snapshot(scene, 0.0);
  CameraSensorConfig plain;
  CameraImager keep(Spec(64, 32, 40), plain, Realtime(), 0, scene);
  CameraImager lean(Spec(64, 32, 40), plain, Realtime(), 0, scene);
  lean.set_keep_radiance(false);
  RadianceOnRequest r_keep(MakeRenderer(scene, Realtime()));
  RadianceOnRequest r_lean(MakeRenderer(scene, Realtime()));
  CameraImages a, b;
  keep.Capture(&r_keep, snap, nullptr, X, nullptr, X, 0, &a);
  lean.Capture(&r_lean, snap, nullptr, X, nullptr, X, 0, &b);
  // the same camera images; the lean one without the radiance, which it never asked for
  ASSERT_FALSE(a.radiance.empty());
  EXPECT_TRUE(b.radiance.empty());
  EXPECT_EQ(b.rgb.data, a.rgb.data);
  EXPECT_EQ(b.ev100, a.ev100);
  EXPECT_EQ(r_keep.asked, std::vector<bool>{true});
  EXPECT_EQ(r_lean.asked, std::vector<bool>{false});
  // the black-frame warning's brightest value: the kept radiance's maximum, and the same
  // value from the frame rendered again with the radiance
  float brightest = 0;
  for (float v : a.radiance.data) brightest = std::max(brightest, v);
  ASSERT_GT(brightest, 0.0f);
  EXPECT_EQ(keep.BrightestRadiance(&r_keep, snap, nullptr, a), brightest);
  EXPECT_EQ(lean.BrightestRadiance(&r_lean, snap, nullptr, b), brightest);
  EXPECT_EQ(r_keep.asked.size(), 1u);  // read from the frame, no render
  EXPECT_EQ(r_lean.asked, (std::vector<bool>{false, true}));

  // the camera model's stages that read the radiance still get it
  CameraSensorConfig noisy = plain, gray = plain, adapting = plain, blurred = plain;
  noisy.noise.enabled = true;
  gray.white_balance.mode = WhiteBalance::Mode::kAuto;
  adapting.auto_exposure_time_constant_sec = 0.5;
  blurred.motion_blur_samples = 2;
  RenderSettings auto_exposure = Realtime();
  auto_exposure.auto_exposure = true;
  for (const auto& [cfg, rs, moving] :
       {std::tuple{noisy, Realtime(), false}, std::tuple{gray, Realtime(), false},
        std::tuple{adapting, auto_exposure, false}, std::tuple{blurred, Realtime(), true}}) {
    CameraImager imager(Spec(64, 32, 40), cfg, rs, 0, scene);
    imager.set_keep_radiance(false);
    RadianceOnRequest r(MakeRenderer(scene, rs));
    const WorldSnapshot end = Snapshot(scene, 0.1);
    CameraImages out;
    imager.Capture(&r, snap, nullptr, X, moving ? &end : nullptr, X, 0, &out);
    EXPECT_FALSE(out.radiance.empty());
    for (bool asked : r.asked) EXPECT_TRUE(asked);
  }
}

TEST(CameraImagerTest, NoiseJpegAndDropletsAreSeededAndLocal) {
  SceneDescription scene = BlackScene();
  scene.sky.radiance = Eigen::Vector3f(0.2f, 0.1f, 0.05f);
  const int m = AddMaterial(&scene, Eigen::Vector3f::Zero(), Eigen::Vector3f(0.05f, 0.2f, 0.1f));
  AddGeom(&scene, GeomShape::kSphere, Eigen::Vector3d(0.5, 0, 0), Eigen::Vector3d(3, 0, 0), m);
  RenderSettings rs = Realtime();
  rs.ev100 = std::log2(0.3 / (0.18 * 1.2));
  auto renderer = MakeRenderer(scene, rs);
  const Pose X = LookingAlongX(Eigen::Vector3d::Zero());
  auto capture = [&](const CameraSensorConfig& cfg, const WorldSnapshot& snap, int64_t frame,
                     const EffectsFrame* fx = nullptr) {
    CameraImager imager(Spec(96, 64, 80), cfg, rs, 1, scene);
    CameraImages im;
    imager.Capture(renderer.get(), snap, fx, X, nullptr, X, frame, &im);
    return im.rgb;
  };
  const WorldSnapshot dry = Snapshot(scene, 0.0);
  CameraSensorConfig clean;
  const ImageU8 base = capture(clean, dry, 0);
  CameraSensorConfig noisy;
  noisy.noise.enabled = true;
  noisy.noise.iso = 3200;
  const ImageU8 n0 = capture(noisy, dry, 0), n0b = capture(noisy, dry, 0),
                n1 = capture(noisy, dry, 1);
  EXPECT_EQ(n0.data, n0b.data);
  EXPECT_NE(n0.data, n1.data);
  EXPECT_NE(n0.data, base.data);
  CameraSensorConfig jpeg;
  jpeg.jpeg_quality = 60;
  const ImageU8 j = capture(jpeg, dry, 0);
  double se = 0;
  for (size_t i = 0; i < j.data.size(); ++i) se += std::pow(double(j.data[i]) - base.data[i], 2);
  const double psnr = 10 * std::log10(255.0 * 255.0 / (se / j.data.size()));
  EXPECT_NE(j.data, base.data);
  EXPECT_GT(psnr, 30.0);
  // droplets appear only in rain and change a small part of the image
  auto fx = std::make_shared<EffectsFrame>();
  ParticleSet rain;
  rain.kind = ParticleKind::kRain;
  rain.position_W.push_back(Eigen::Vector3f(50, 50, 50));  // far out of view
  rain.velocity_W.push_back(Eigen::Vector3f(0, 0, -5));
  rain.radius_m.push_back(0.001f);
  fx->particles.push_back(rain);
  EXPECT_TRUE(IsRaining(fx.get()));
  CameraSensorConfig drops;
  drops.lens_droplet_count = 3;
  const ImageU8 d = capture(drops, dry, 0, fx.get());
  int changed = 0;
  for (size_t i = 0; i < d.data.size(); i += 3)
    changed += d.data[i] != base.data[i] || d.data[i + 1] != base.data[i + 1];
  EXPECT_GT(changed, 20);
  EXPECT_LT(changed, 96 * 64 / 3);
  EXPECT_EQ(capture(drops, dry, 0).data, base.data);
}

// lens droplets follow the shelter map at the camera: none under a roof in the rain, drops
// under open sky, fading over kDropletLifetimeSec after the camera goes indoors.
TEST(CameraImagerTest, LensDropletsOnlyUnderOpenSky) {
  SceneDescription scene = BlackScene();
  scene.sky.radiance = Eigen::Vector3f(0.2f, 0.1f, 0.05f);
  const int m = AddMaterial(&scene, Eigen::Vector3f::Zero(), Eigen::Vector3f(0.05f, 0.2f, 0.1f));
  AddGeom(&scene, GeomShape::kSphere, Eigen::Vector3d(0.5, 0, 0), Eigen::Vector3d(3, 0, 0), m);
  AddGeom(&scene, GeomShape::kSphere, Eigen::Vector3d(0.5, 0, 0), Eigen::Vector3d(3, 5, 0), m);
  // a static roof 1 m above the origin (the world body)
  AddGeom(&scene, GeomShape::kBox, Eigen::Vector3d(1, 1, 0.05), Eigen::Vector3d(0, 0, 1), m);
  RenderSettings rs = Realtime();
  rs.ev100 = std::log2(0.3 / (0.18 * 1.2));
  auto renderer = MakeRenderer(scene, rs);
  const Pose indoors = LookingAlongX(Eigen::Vector3d::Zero());
  const Pose outdoors = LookingAlongX(Eigen::Vector3d(0, 5, 0));
  auto fx = std::make_shared<EffectsFrame>();
  ParticleSet rain;
  rain.kind = ParticleKind::kRain;
  rain.position_W.push_back(Eigen::Vector3f(50, 50, 50));  // far out of view
  rain.velocity_W.push_back(Eigen::Vector3f(0, 0, -5));
  rain.radius_m.push_back(0.001f);
  fx->particles.push_back(rain);
  CameraSensorConfig drops;
  drops.lens_droplet_count = 3;
  CameraSensorConfig dry_lens;
  dry_lens.lens_droplets = false;
  auto capture = [&](CameraImager* imager, const Pose& X, double t) {
    CameraImages im;
    imager->Capture(renderer.get(), Snapshot(scene, t), fx.get(), X, nullptr, X, 0, &im);
    return im.rgb;
  };
  auto reference = [&](const Pose& X, double t) {
    CameraImager imager(Spec(96, 64, 80), dry_lens, rs, 1, scene);
    return capture(&imager, X, t);
  };
  // indoors in the rain: no drops at all
  {
    CameraImager imager(Spec(96, 64, 80), drops, rs, 1, scene);
    EXPECT_EQ(capture(&imager, indoors, 0.0).data, reference(indoors, 0.0).data);
  }
  // outdoors: drops; then indoors they stay a while (fading) and are gone after the lifetime
  CameraImager imager(Spec(96, 64, 80), drops, rs, 1, scene);
  EXPECT_NE(capture(&imager, outdoors, 0.0).data, reference(outdoors, 0.0).data);
  EXPECT_NE(capture(&imager, indoors, 0.5).data, reference(indoors, 0.5).data);
  EXPECT_EQ(capture(&imager, indoors, 0.5 + kDropletLifetimeSec).data,
            reference(indoors, 0.5 + kDropletLifetimeSec).data);
  EXPECT_EQ(LensDropletCount(6, std::nullopt, 1.0), 0);
  EXPECT_EQ(LensDropletCount(6, 1.0, 1.0), 6);
  EXPECT_EQ(LensDropletCount(6, 1.0, 1.0 + 0.5 * kDropletLifetimeSec), 3);
  EXPECT_EQ(LensDropletCount(6, 1.0, 1.0 + kDropletLifetimeSec), 0);
}

TEST(CameraImagerTest, ThreadCountDoesNotChangeTheImages) {
  SceneDescription scene = BlackScene();
  scene.sky.radiance = Eigen::Vector3f(0.2f, 0.1f, 0.05f);
  const int m =
      AddMaterial(&scene, Eigen::Vector3f(0.5f, 0.5f, 0.5f), Eigen::Vector3f(0.3f, 0.2f, 0.1f));
  AddGeom(&scene, GeomShape::kSphere, Eigen::Vector3d(0.8, 0, 0), Eigen::Vector3d(3, 0, 0), m);
  CameraSensorConfig cfg;
  cfg.noise.enabled = true;
  cfg.motion_blur_samples = 3;
  cfg.rolling_shutter_line_time_sec = 1e-4;
  cfg.depth_noise.preset = "kinect_v2";
  CameraSpec spec = Spec(64, 48, 50);
  spec.outputs[ImageKind::kDepth] = true;
  const Pose X0 = LookingAlongX(Eigen::Vector3d::Zero());
  const Pose X1 = LookingAlongX(Eigen::Vector3d(0, -0.05, 0.01));
  auto run = [&](int threads) {
    RenderSettings rs = Realtime();
    rs.threads = threads;
    auto renderer = MakeRenderer(scene, rs);
    CameraImager imager(spec, cfg, rs, 2, scene);
    const WorldSnapshot a = Snapshot(scene, 0), b = Snapshot(scene, 0.02);
    CameraImages im;
    imager.Capture(renderer.get(), a, nullptr, X0, &b, X1, 4, &im);
    return im;
  };
  const CameraImages one = run(1), two = run(2);
  EXPECT_EQ(one.rgb.data, two.rgb.data);
  EXPECT_EQ(one.depth_m.data, two.depth_m.data);
}

TEST(CameraImagerTest, BadSettingsNameCameraAndKey) {
  CameraSensorConfig cfg;
  cfg.exposure_time_sec = -1;
  try {
    ValidateCameraSensorOrThrow(cfg, "cameras[front]");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "cameras[front].exposure_time_sec");
  }
  cfg = CameraSensorConfig();
  cfg.depth_noise.preset = "nope";
  EXPECT_THROW(ValidateCameraSensorOrThrow(cfg, "c"), ConfigError);
  cfg = CameraSensorConfig();
  cfg.jpeg_quality = 101;
  EXPECT_THROW(ValidateCameraSensorOrThrow(cfg, "c"), ConfigError);
}

TEST(CameraImagerTest, FoldingDistortionIsRejected) {
  CameraIntrinsics k = CameraIntrinsics::FromFovy(640, 480, 90);
  k.k1 = -0.28;
  k.k2 = 0.07;
  k.k3 = -0.01;  // at 90 deg vertical fov the corners lie beyond the fold radius
  EXPECT_THROW(Camera(Pose::Identity(), k), ConfigError);
  k = CameraIntrinsics::FromFovy(640, 480, 50);
  k.k1 = -0.28;
  k.k2 = 0.07;
  k.k3 = -0.01;
  EXPECT_NO_THROW(Camera(Pose::Identity(), k));
  // Newton inverse is exact
  double x, y, xd, yd;
  ASSERT_TRUE(UndistortNormalized(k, 0.4, -0.3, &x, &y));
  DistortNormalized(k, x, y, &xd, &yd);
  EXPECT_NEAR(xd, 0.4, 1e-12);
  EXPECT_NEAR(yd, -0.3, 1e-12);
}

}  // namespace
}  // namespace penumbra
