// the bundled worlds' cameras under their profiles (sensors/camera_profile.h): no large flat
// clipped area in any first frame, and a dark world darker and noisier than the daylight room.
// frames are rendered small (160 x 120, the same field of view) to keep the suite fast.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "penumbra/bench/preset_scene.h"
#include "penumbra/scene/camera_pose.h"
#include "penumbra/sensors/camera_imager.h"
#include "penumbra/world/camera_specs.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

constexpr int kWidth = 160, kHeight = 120;

// the first two frames of camera `index` of a loaded world, at kWidth x kHeight, captured at
// the world's start (nothing moves; the second frame has fresh temporal noise)
struct TwoFrames {
  CameraImages first, second;
};

TwoFrames CaptureStart(PresetScene& p, const WorldConfig& world, int index) {
  const SceneDescription& scene = p.session->scene();
  CameraSpec spec = scene.cameras.at(index);
  spec.intrinsics = CameraIntrinsics::FromFovy(kWidth, kHeight, spec.intrinsics.fovy_deg());
  spec.outputs = CameraOutputs{ImageKind::kRgb};
  const std::vector<CameraSensorConfig> cfg = SensorConfigsFor(scene, world);
  CameraImager imager(spec, cfg.at(index), world.render, index, scene);
  const WorldSnapshot snap = p.session->sim().Snapshot();
  const Pose X_WO = CameraPoseInWorld(scene.cameras.at(index), snap);
  const auto fx = p.session->effects().Evaluate(snap, X_WO.translation());
  TwoFrames out;
  imager.Capture(p.session->renderer(), snap, fx.get(), X_WO, nullptr, X_WO, 0, &out.first);
  imager.Capture(p.session->renderer(), snap, fx.get(), X_WO, nullptr, X_WO, 1, &out.second);
  return out;
}

double FullScaleFraction(const ImageU8& rgb) {
  int n = 0;
  for (size_t i = 0; i + 2 < rgb.data.size(); i += 3)
    n += rgb.data[i] == 255 && rgb.data[i + 1] == 255 && rgb.data[i + 2] == 255;
  return static_cast<double>(n) / (rgb.width * rgb.height);
}

double Mean(const ImageU8& rgb) {
  double s = 0;
  for (uint8_t v : rgb.data) s += v;
  return s / rgb.data.size();
}

// the temporal noise of a still view: the standard deviation of two frames' difference / sqrt 2
double TemporalNoise(const TwoFrames& f) {
  double s = 0, s2 = 0;
  const size_t n = f.first.rgb.data.size();
  for (size_t i = 0; i < n; ++i) {
    const double d = static_cast<double>(f.first.rgb.data[i]) - f.second.rgb.data[i];
    s += d;
    s2 += d * d;
  }
  return std::sqrt(0.5 * (s2 / n - (s / n) * (s / n)));
}

std::vector<std::string> WorldsWithCameras() {
  std::vector<std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(fs::path(PENUMBRA_SOURCE_DIR) / "worlds")) {
    if (!e.is_regular_file() || e.path().extension() != ".yaml") continue;
    if (e.path().parent_path().filename() == "adversity") continue;  // preset files
    out.push_back(e.path().string());
  }
  std::sort(out.begin(), out.end());
  return out;
}

TEST(CameraProfileWorlds, NoFirstFrameHasALargeFlatClippedArea) {
  int cameras = 0;
  for (const std::string& file : WorldsWithCameras()) {
    const WorldConfig world = LoadWorldFile(file);
    if (world.cameras.empty()) continue;
    PresetScene p = LoadPresetScene(world, "");
    for (size_t i = 0; i < p.session->scene().cameras.size(); ++i) {
      SCOPED_TRACE(file + " camera " + p.session->scene().cameras[i].name);
      const TwoFrames f = CaptureStart(p, world, static_cast<int>(i));
      EXPECT_LT(FullScaleFraction(f.first.rgb), 0.01);
      ++cameras;
    }
  }
  EXPECT_GE(cameras, 30);
}

TEST(CameraProfileWorlds, TheNightWorldIsDarkerAndNoisierThanTheDaylightRoom) {
  const std::string root = std::string(PENUMBRA_SOURCE_DIR) + "/worlds/";
  const WorldConfig day = LoadWorldFile(root + "default.yaml");
  const WorldConfig night = LoadWorldFile(root + "effects/flashlight.yaml");
  PresetScene pd = LoadPresetScene(day, ""), pn = LoadPresetScene(night, "");
  const TwoFrames d = CaptureStart(pd, day, 0), n = CaptureStart(pn, night, 0);
  EXPECT_LT(Mean(n.first.rgb), Mean(d.first.rgb) - 10);
  EXPECT_GT(TemporalNoise(n), 2 * TemporalNoise(d));
  // the gain is what lifts the night: far above the day's
  EXPECT_GT(n.first.analog_gain, 4 * d.first.analog_gain);
  EXPECT_GT(n.first.exposure_time_sec, d.first.exposure_time_sec);
}

}  // namespace
}  // namespace penumbra
