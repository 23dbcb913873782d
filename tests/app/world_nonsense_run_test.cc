// on the real binary: nonsense that `penumbra run` used to accept silently now
// exits 2 naming the file:line (world files) or the flag (command line), or gets a warning:
// `fovy_deg: 1e-300` (fx = 2.75e303), a YAML tag, `--out ""` (fell back to the world's folder),
// a 100 KB camera name (exit 1, no line, 100 KB of stderr), and black frames (a world without
// light, an exposure far too dark, a camera that no light reaches) that ran without a word.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "app/child_process.h"
#include "common/temp_dir.h"
#include "penumbra/world/run_budget.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

constexpr char kNonsenseBox[] = R"(<mujoco model="m">
  <option timestep="0.01"/>
  <worldbody>
    <geom name="floor" type="plane" size="3 3 0.1"/>
    <body name="box" pos="0 0 0.5"><freejoint/><geom type="box" size="0.2 0.2 0.2"/></body>
    <geom name="crate" type="box" pos="2 0 1" size="0.5 0.5 0.5"/>
  </worldbody>
</mujoco>)";

// a world of the box model with a small camera `c` (keys in `camera`) and `extra` top-level keys
std::string NonsenseWorld(const std::string& camera, const std::string& extra = "") {
  return "duration_sec: 0.05\n"
         "models: [{name: m, file: m.xml}]\n"
         "mjcf_cameras: {enabled: false}\n"
         "cameras:\n"
         "  - {name: c, pose: {xyz: [-2, 0, 1]}, width: 16, height: 12" +
         camera + "}\n" + extra;
}

class WorldNonsenseRunTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_.Write("m.xml", kNonsenseBox); }

  testing::ProcessResult Run(const std::string& world_text, std::vector<std::string> extra = {}) {
    const std::string world = dir_.Write("w" + std::to_string(++runs_) + ".yaml", world_text);
    std::vector<std::string> args = {"run", world, "-q"};
    if (std::find(extra.begin(), extra.end(), "--out") == extra.end() &&
        std::find(extra.begin(), extra.end(), "-o") == extra.end()) {
      args.push_back("--out");
      args.push_back((dir_.path() / ("out" + std::to_string(runs_))).string());
    }
    args.insert(args.end(), extra.begin(), extra.end());
    return testing::RunPenumbra(args, dir_.path());
  }

  std::string WorldPath() const {
    return (dir_.path() / ("w" + std::to_string(runs_) + ".yaml")).string();
  }

  testing::TempDir dir_;
  int runs_ = 0;
};

TEST_F(WorldNonsenseRunTest, TinyFieldOfViewExits2WithTheLine) {
  const testing::ProcessResult r = Run(NonsenseWorld(", fovy_deg: 1e-300"));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find(WorldPath() + ":5: cameras[0].fovy_deg: got 1e-300; expected [0.1, 179)"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(dir_.path() / "out1" / "c")) << "nothing rendered";
}

TEST_F(WorldNonsenseRunTest, YamlTagExits2WithTheLine) {
  const testing::ProcessResult r = Run(NonsenseWorld("", "seed: !foo 3\n"));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find(WorldPath() + ":6: YAML tag '!foo' is not supported"), std::string::npos)
      << r.err;
}

TEST_F(WorldNonsenseRunTest, OverlongCameraNameExits2WithTheLineAndABoundedMessage) {
  std::string world = NonsenseWorld("");
  world.replace(world.find("name: c,"), 8, "name: " + std::string(100000, 'c') + ",");
  const testing::ProcessResult r = Run(world);
  EXPECT_EQ(r.exit_code, 2) << r.err.substr(0, 2000);
  EXPECT_NE(r.err.find(WorldPath() + ":5: cameras[0].name: a name of 100000 characters"),
            std::string::npos)
      << r.err.substr(0, 2000);
  EXPECT_LT(r.err.size(), 1000u) << r.err.substr(0, 2000);
}

TEST_F(WorldNonsenseRunTest, EmptyPathFlagsExit2NamingTheFlag) {
  const std::string world = NonsenseWorld("", "output: {dir: world_out}\n");
  struct Case {
    std::vector<std::string> args;
    std::string message;
  };
  const std::vector<Case> cases = {
      {{"--out", ""}, "<command line>: --out: an empty value; expected a non-empty value"},
      {{"-o", ""}, "--out: an empty value"},
      {{"--record", ""}, "--record: an empty value"},
      {{"--override", ""}, "--override: an empty value"},
      {{"--adversity", ""}, "--adversity: an empty value"},
  };
  for (const Case& c : cases) {
    const testing::ProcessResult r = Run(world, c.args);
    EXPECT_EQ(r.exit_code, 2) << c.args[0] << ": " << r.err;
    EXPECT_EQ(r.out, "");
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.args[0] << ": " << r.err;
  }
  // `--out ""` used to write into the world's output.dir
  EXPECT_FALSE(fs::exists(dir_.path() / "world_out"));
  // an empty world argument
  const testing::ProcessResult r = testing::RunPenumbra({"run", ""}, dir_.path());
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("world: an empty value; expected a non-empty argument"), std::string::npos)
      << r.err;
  // `--zmq` without a value still means the default endpoint (checked elsewhere); a bare flag
  // with no value is not an empty value
}

TEST_F(WorldNonsenseRunTest, AWorldWithoutLightWarnsOncePerCamera) {
  const testing::ProcessResult r =
      Run(NonsenseWorld("", "sky: {type: uniform, luminance_cd_m2: 0}\n"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string warning = "camera 'c': frame 0 (t = 0 s) is black";
  const size_t at = r.err.find(warning);
  ASSERT_NE(at, std::string::npos) << r.err;
  EXPECT_NE(r.err.find("the world has no light", at), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("is black", at + warning.size()), std::string::npos) << "once: " << r.err;
}

TEST_F(WorldNonsenseRunTest, AnExposureFarTooDarkWarns) {
  const testing::ProcessResult r =
      Run(NonsenseWorld("",
                        "render: {exposure: {mode: manual, ev100: 30}}\n"
                        "lights: [{name: l, type: point, position: [0, 0, 2], intensity_cd: 50}]\n"
                        "sky: {type: uniform, luminance_cd_m2: 1}\n"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("camera 'c': frame 0 (t = 0 s) is black"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("manual exposure ev100 30"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("the exposure is too dark"), std::string::npos) << r.err;
}

TEST_F(WorldNonsenseRunTest, ACameraThatNoLightReachesWarns) {
  // the world's only light is a narrow spot pointing at the empty sky (and the sky is black):
  // the world has light, but nothing the camera sees is lit
  const testing::ProcessResult r = Run(
      NonsenseWorld("",
                    "sky: {type: uniform, luminance_cd_m2: 0}\n"
                    "lights: [{name: up, type: spot, position: [0, 0, 2.5], direction: [0, 0, 1], "
                    "intensity_cd: 100, inner_angle_deg: 5, outer_angle_deg: 10}]\n"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("camera 'c': frame 0 (t = 0 s) is black"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("no light reaches it: the camera may be inside a model's geometry"),
            std::string::npos)
      << r.err;
}

TEST_F(WorldNonsenseRunTest, ALitWorldDoesNotWarn) {
  const testing::ProcessResult r =
      Run(NonsenseWorld("",
                        "lights: [{name: sun, type: sun, direction: [0.3, 0.2, -1], "
                        "illuminance_lux: 20000}]\n"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err.find("is black"), std::string::npos) << r.err;
}

TEST(RunBudgetPathSamples, HugeSampleCountsOfThePathtracedTierAreWarned) {
  // the reported case: --spp 65536 at 64 x 48, about 20 minutes a frame; 1 s at 10 Hz
  WorldConfig world;
  world.duration_sec = 1;
  world.render.tier = RenderSettings::Tier::kPathtraced;
  world.render.samples_per_pixel = 65536;
  SceneDescription scene;
  CameraSpec cam;
  cam.name = "c";
  cam.intrinsics = CameraIntrinsics::FromFovy(64, 48, 60);
  scene.cameras = {cam};
  RunWork w = EstimateRunWork(world, scene, 0.01);
  EXPECT_DOUBLE_EQ(w.path_samples, 11 * 64.0 * 48 * 65536);
  const auto text = DescribeRunWork(w);
  ASSERT_TRUE(text);
  EXPECT_NE(text->find("2.21e+09 path samples (pathtraced: pixels x samples_per_pixel x frames)"),
            std::string::npos)
      << *text;
  EXPECT_NE(text->find("render.samples_per_pixel (--spp)"), std::string::npos) << *text;
  // the default 16 spp is far below; the realtime tier traces no path samples
  world.render.samples_per_pixel = 16;
  EXPECT_FALSE(DescribeRunWork(EstimateRunWork(world, scene, 0.01)));
  world.render.samples_per_pixel = 65536;
  world.render.tier = RenderSettings::Tier::kRealtime;
  EXPECT_EQ(EstimateRunWork(world, scene, 0.01).path_samples, 0);
}

}  // namespace
}  // namespace penumbra
