// the bundled default world loads, runs, moves the robot and renders deterministically.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "penumbra/app/runner.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

std::string ReadAll(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// last row of trajectory.csv as numbers
std::vector<double> LastRow(const fs::path& csv) {
  std::ifstream f(csv);
  std::string line, last;
  while (std::getline(f, line)) last = line;
  std::vector<double> v;
  std::stringstream ss(last);
  std::string cell;
  while (std::getline(ss, cell, ',')) v.push_back(std::stod(cell));
  return v;
}

TEST(DefaultWorldTest, RunsDeterministicallyAndTheRoverDrives) {
  const fs::path dir = fs::temp_directory_path() / ("penumbra_default_world_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  WorldConfig world = LoadWorldFile(PENUMBRA_SOURCE_DIR "/worlds/default.yaml");
  ASSERT_FALSE(world.cameras.empty());
  RunOptions options;
  options.progress = false;
  options.duration_sec = 1.0;
  // keep the images small: the test is about the pipeline, not resolution
  for (CameraConfig& c : world.cameras) {
    c.width = 160;
    c.height = 120;
  }
  world.render.threads = 1;
  options.out_dir = (dir / "a").string();
  const RunSummary a = RunWorld(world, options);
  world.render.threads = 2;
  options.out_dir = (dir / "b").string();
  RunWorld(world, options);

  const std::string cam = world.cameras.front().name;
  EXPECT_EQ(a.frames_per_camera.at(cam), static_cast<int64_t>(world.cameras.front().rate_hz) + 1);
  for (const char* file : {"trajectory.csv", "composed.xml"})
    EXPECT_TRUE(ReadAll(dir / "a" / file) == ReadAll(dir / "b" / file)) << file;
  for (const auto& e : fs::recursive_directory_iterator(dir / "a" / cam)) {
    if (!e.is_regular_file()) continue;
    const fs::path rel = fs::relative(e.path(), dir / "a");
    EXPECT_TRUE(ReadAll(e.path()) == ReadAll(dir / "b" / rel)) << rel;
  }

  // the rover's free joint comes first in qpos (robots are composed before models):
  // after 1 s at 0.5 m/s cruise it has moved a noticeable distance
  const std::vector<double> last = LastRow(dir / "a" / "trajectory.csv");
  std::ifstream f(dir / "a" / "trajectory.csv");
  std::string header, first_line;
  std::getline(f, header);
  std::getline(f, first_line);
  std::vector<double> first;
  std::stringstream ss(first_line);
  std::string cell;
  while (std::getline(ss, cell, ',')) first.push_back(std::stod(cell));
  const double moved = std::hypot(last[2] - first[2], last[3] - first[3]);
  EXPECT_GT(moved, 0.2) << "rover barely moved";
  EXPECT_LT(moved, 0.6) << "rover faster than its 0.5 m/s cruise";
  fs::remove_all(dir);
}

}  // namespace
}  // namespace penumbra
