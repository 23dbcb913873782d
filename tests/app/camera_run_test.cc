// end-to-end camera outputs of `penumbra run`: distortion, motion blur + rolling shutter (end
// snapshots from the physics thread), sensor and depth noise, stereo, semantic classes,
// camera_info; byte-identical on a second run.

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "common/temp_dir.h"
#include "penumbra/run/runner.h"
#include "penumbra/core/error.h"
#include "penumbra/output/png_io.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

constexpr char kMjcf[] = R"(
<mujoco model="ball">
  <option timestep="0.005"/>
  <asset><material name="concrete" rgba="0.6 0.6 0.6 1"/></asset>
  <worldbody>
    <geom name="floor" type="plane" size="3 3 0.1" material="concrete"/>
    <body name="ball" pos="0 0 0.6">
      <freejoint/>
      <geom name="ball" type="sphere" size="0.25" rgba="0.9 0.3 0.2 1"/>
    </body>
  </worldbody>
</mujoco>)";

constexpr char kWorld[] = R"(seed: 5
duration_sec: 0.25
models:
  - {name: scene, file: ball.xml}
lights:
  - {name: sun, type: sun, direction: [0.3, 0.4, -1], illuminance_lux: 20000}
mjcf_cameras: {enabled: false}
semantic_classes:
  - {name: ball, id: 2, bodies: ["scene/ball"]}
  - {name: ground, id: 9, materials: ["*concrete"]}
cameras:
  - name: rig
    pose: {xyz: [-2, 0, 0.8], rpy_deg: [0, 10, 0]}
    width: 48
    height: 36
    fovy_deg: 60
    rate_hz: 10
    outputs: [rgb, depth, segmentation, range, normals, instance_segmentation, semantic_segmentation]
    distortion: {k1: -0.2, k2: 0.05, p1: 0.001}
    exposure_time_sec: 0.02
    motion_blur_samples: 3
    rolling_shutter_line_time_sec: 0.0001
    noise: {iso: 400}
    depth_noise: {preset: kinect_v2}
    stereo: {baseline_m: 0.1}
)";

using testing::ReadAll;

class CameraRunTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("penumbra_camera_run_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    std::ofstream(dir_ / "ball.xml") << kMjcf;
    std::ofstream(dir_ / "world.yaml") << kWorld;
  }
  void TearDown() override { fs::remove_all(dir_); }
  RunSummary Run(const std::string& out) {
    WorldConfig world = LoadWorldFile((dir_ / "world.yaml").string());
    RunOptions options;
    options.out_dir = (dir_ / out).string();
    options.progress = false;
    return RunWorld(world, options);
  }
  fs::path dir_;
};

TEST_F(CameraRunTest, WritesEveryCameraOutputDeterministically) {
  const RunSummary s = Run("a");
  // frames at 0, 0.1, 0.2 s; each needs an end snapshot 0.02 + 35 * 1e-4 s later
  EXPECT_EQ(s.frames_per_camera.at("rig/left"), 3);
  EXPECT_EQ(s.frames_per_camera.at("rig/right"), 3);
  const fs::path out = dir_ / "a";
  for (const char* cam : {"rig/left", "rig/right"})
    for (const char* sub : {"rgb", "depth", "segmentation", "range", "normals",
                            "instance_segmentation", "semantic_segmentation"})
      EXPECT_TRUE(fs::exists(out / cam / sub / "000002.png")) << cam << " " << sub;
  const nlohmann::json info = nlohmann::json::parse(ReadAll(out / "camera_info.json"));
  EXPECT_EQ(info["rig/left"]["distortion_model"], "plumb_bob");
  EXPECT_EQ(info["rig/left"]["D"][0].get<double>(), -0.2);
  EXPECT_NEAR(info["rig/right"]["P"][3].get<double>(),
              -0.1 * info["rig/right"]["K"][0].get<double>(), 1e-9);
  EXPECT_TRUE(fs::exists(out / "camera_info.yaml"));
  const nlohmann::json labels = nlohmann::json::parse(ReadAll(out / "semantic_classes.json"));
  EXPECT_EQ(labels["ball"], 2);
  EXPECT_EQ(labels["ground"], 9);
  // semantic classes: the ball (2) and the concrete floor (9) are both in view, nothing else
  const PngImage sem = ReadPng((out / "rig/left/semantic_segmentation/000000.png").string());
  std::set<int> classes(sem.samples.begin(), sem.samples.end());
  EXPECT_TRUE(classes.count(2));
  EXPECT_TRUE(classes.count(9));
  for (int c : classes) EXPECT_TRUE(c == 0 || c == 2 || c == 9) << c;
  // instance ids are body index + 1: the ball's pixels carry the same instance id
  const PngImage inst = ReadPng((out / "rig/left/instance_segmentation/000000.png").string());
  for (size_t i = 0; i < sem.samples.size(); ++i) {
    if (sem.samples[i] == 2) {
      EXPECT_GE(inst.samples[i], 2);
    }
  }
  // frames.csv: mid-exposure time (sub-frame 1 of 3 at T / 2 = 0.01 s)
  const std::string csv = ReadAll(out / "rig/left/frames.csv");
  const size_t row = csv.find("\n0,");
  ASSERT_NE(row, std::string::npos) << csv;
  EXPECT_NEAR(std::stod(csv.substr(row + 3)), 0.01, 1e-12) << csv;
  // same seed, same bytes
  Run("b");
  for (const auto& e : fs::recursive_directory_iterator(out)) {
    if (!e.is_regular_file() || e.path().filename() == "run.json") continue;
    const fs::path rel = fs::relative(e.path(), out);
    EXPECT_EQ(ReadAll(e.path()), ReadAll(dir_ / "b" / rel)) << rel;
  }
}

TEST_F(CameraRunTest, FoldingDistortionIsAConfigErrorAtLoad) {
  std::ofstream(dir_ / "bad.yaml") << "cameras:\n  - name: fish\n    fovy_deg: 100\n"
                                      "    distortion: {k1: -0.5}\n";
  try {
    LoadWorldFile((dir_ / "bad.yaml").string());
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "cameras[0].distortion");
    EXPECT_NE(std::string(e.what()).find("camera 'fish'"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace penumbra
