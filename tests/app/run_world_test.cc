// end-to-end: world file -> composer -> physics thread -> renderer -> files.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "common/temp_dir.h"
#include "penumbra/app/cli.h"
#include "penumbra/run/runner.h"
#include "penumbra/core/error.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

constexpr char kBallMjcf[] = R"(
<mujoco model="ball">
  <option timestep="0.005"/>
  <asset>
    <texture name="grid" type="2d" builtin="checker" rgb1="0.2 0.3 0.4" rgb2="0.8 0.8 0.8" width="64" height="64"/>
    <material name="grid" texture="grid" texrepeat="4 4"/>
  </asset>
  <worldbody>
    <geom name="floor" type="plane" size="3 3 0.1" material="grid"/>
    <body name="ball" pos="0 0 1">
      <freejoint/>
      <geom name="ball" type="sphere" size="0.2" rgba="0.9 0.3 0.2 1"/>
    </body>
    <body name="box" pos="0.5 0.3 0.6" euler="10 20 30">
      <freejoint/>
      <geom name="box" type="box" size="0.15 0.1 0.1" rgba="0.2 0.7 0.3 1"/>
    </body>
    <camera name="overhead" pos="0 -3 2" xyaxes="1 0 0 0 0.6 0.8"/>
  </worldbody>
</mujoco>)";

using testing::ReadAll;

class RunWorldTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("penumbra_run_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    std::ofstream(dir_ / "ball.xml") << kBallMjcf;
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path WriteWorld(const std::string& extra) {
    const fs::path world = dir_ / "world.yaml";
    std::ofstream(world) << "seed: 3\n"
                            "duration_sec: 0.5\n"
                            "models:\n"
                            "  - {name: scene, file: ball.xml}\n"
                            "lights:\n"
                            "  - {name: sun, type: sun, direction: [0.3, 0.4, -1], illuminance_lux: 20000}\n"
                            "  - {name: lamp, type: point, position: [0, 0, 2.5], intensity_cd: 200, radius_m: 0.1}\n"
                            "cameras:\n"
                            "  - {name: cam, attach: world, pose: {xyz: [-3, 0, 1.5], rpy_deg: [0, 20, 0]},\n"
                            "     width: 64, height: 48, fovy_deg: 60, rate_hz: 10,\n"
                            "     outputs: [rgb, depth, segmentation]}\n"
                            "mjcf_cameras: {width: 32, height: 24, rate_hz: 5}\n"
                         << extra;
    return world;
  }

  RunSummary Run(const fs::path& world_file, const std::string& out, int threads) {
    WorldConfig world = LoadWorldFile(world_file.string());
    world.render.threads = threads;
    RunOptions options;
    options.out_dir = (dir_ / out).string();
    options.progress = false;
    return RunWorld(world, options);
  }

  fs::path dir_;
};

// every file under a, with its bytes, except run.json (timings differ)
std::map<std::string, std::string> Tree(const fs::path& root) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(root)) {
    if (!e.is_regular_file() || e.path().filename() == "run.json") continue;
    files[fs::relative(e.path(), root).string()] = ReadAll(e.path());
  }
  return files;
}

TEST_F(RunWorldTest, WritesEveryOutputAtTheCameraRates) {
  const RunSummary s = Run(WriteWorld(""), "out", 0);
  const fs::path out = dir_ / "out";
  // 0.5 s at 10 Hz: frames at 0, 0.1, ..., 0.5
  EXPECT_EQ(s.frames_per_camera.at("cam"), 6);
  // the MJCF camera at 5 Hz: 0, 0.2, 0.4
  EXPECT_EQ(s.frames_per_camera.at("scene/overhead"), 3);
  for (const char* sub : {"rgb", "depth", "segmentation"})
    EXPECT_TRUE(fs::exists(out / "cam" / sub / "000005.png")) << sub;
  EXPECT_TRUE(fs::exists(out / "scene" / "overhead" / "rgb" / "000002.png"));
  EXPECT_TRUE(fs::exists(out / "composed.xml"));
  EXPECT_TRUE(fs::exists(out / "run.json"));
  EXPECT_TRUE(fs::exists(out / "cam" / "intrinsics.json"));

  // frames.csv: one row per frame, sim time at capture
  std::ifstream csv(out / "cam" / "frames.csv");
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line, "frame,time_sec,x,y,z,qw,qx,qy,qz");
  std::vector<double> times;
  while (std::getline(csv, line)) {
    std::stringstream ss(line);
    std::string frame, t;
    std::getline(ss, frame, ',');
    std::getline(ss, t, ',');
    times.push_back(std::stod(t));
  }
  ASSERT_EQ(times.size(), 6u);
  for (size_t k = 0; k < times.size(); ++k) EXPECT_NEAR(times[k], 0.1 * k, 1e-9);

  // trajectory: 0.5 s / 0.005 s = 100 steps, the ball fell
  std::ifstream traj(out / "trajectory.csv");
  int rows = -1;
  std::string last;
  while (std::getline(traj, line)) {
    ++rows;
    last = line;
  }
  EXPECT_EQ(rows, 100);

  // run.json's render time and its parts: the first frames (renderer set-up on first use) and
  // the time inside Renderer::Render are parts of it
  const nlohmann::json t = nlohmann::json::parse(ReadAll(out / "run.json")).at("timings_sec");
  const double render = t.at("render_sec").get<double>();
  const double first = t.at("render_first_frames_sec").get<double>();
  const double renderer = t.at("render_renderer_sec").get<double>();
  EXPECT_GT(first, 0.0);
  EXPECT_GT(renderer, 0.0);
  EXPECT_LE(first, render);
  EXPECT_LE(renderer, render);
}

TEST_F(RunWorldTest, SameSeedGivesByteIdenticalOutputsForAnyThreadCount) {
  const fs::path world = WriteWorld("");
  Run(world, "a", 1);
  Run(world, "b", 2);
  Run(world, "c", 2);
  const auto a = Tree(dir_ / "a"), b = Tree(dir_ / "b"), c = Tree(dir_ / "c");
  ASSERT_GT(a.size(), 20u);
  ASSERT_EQ(a.size(), b.size());
  for (const auto& [name, bytes] : a) {
    ASSERT_TRUE(b.count(name)) << name;
    EXPECT_TRUE(bytes == b.at(name)) << name << " differs between 1 and 2 render threads";
    EXPECT_TRUE(bytes == c.at(name)) << name << " differs between two runs";
  }
}

TEST_F(RunWorldTest, BareModelRunGetsADefaultCamera) {
  WorldConfig world = WorldForBareModel((dir_ / "ball.xml").string());
  world.duration_sec = 0.1;
  world.cameras.at(0).width = 32;
  world.cameras.at(0).height = 24;
  RunOptions options;
  options.out_dir = (dir_ / "bare").string();
  options.progress = false;
  const RunSummary s = RunWorld(world, options);
  EXPECT_GE(s.frames_per_camera.at("default"), 3);
  EXPECT_TRUE(fs::exists(dir_ / "bare" / "default" / "rgb" / "000000.png"));
}

TEST_F(RunWorldTest, CliReportsBadInputWithExitCode2) {
  const fs::path world = dir_ / "bad.yaml";
  std::ofstream(world) << "seed: 1\nduration_sec: -2\n";
  std::string w = world.string(), o = (dir_ / "o").string();
  const char* argv[] = {"penumbra", "run", w.c_str(), "--out", o.c_str(), "--quiet"};
  EXPECT_EQ(RunCli(6, const_cast<char**>(argv)), 2);
}

TEST_F(RunWorldTest, UnknownAttachBodyNamesTheKey) {
  const fs::path world = dir_ / "attach.yaml";
  std::ofstream(world)
      << "duration_sec: 0.1\nmodels: [{name: scene, file: ball.xml}]\n"
         "cameras: [{name: c, attach: scene/nope, width: 8, height: 8, rate_hz: 1}]\n";
  try {
    Run(world, "x", 1);
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("cameras[0].attach"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("scene/nope"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace penumbra
