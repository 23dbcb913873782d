// the policy we trained ourselves (worlds/models/policies/go1_velocity.onnx) walking the
// default room's waypoint loop through the `policy` controller (worlds/quadruped_policy.yaml):
// a short episode of the real world file, cameras left out, checks that the robot covers
// ground along its first leg and stays upright. the longer evaluation (10 seeds, tracking
// within 20 %) is train/evaluate.py, a benchmark (docs/policies.md).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "penumbra/run/runner.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

const char kPolicyWorld[] = PENUMBRA_SOURCE_DIR "/worlds/quadruped_policy.yaml";

// rows of trajectory.csv (step, time_sec, qpos...) as numbers
std::vector<std::vector<double>> ReadPolicyTrajectory(const fs::path& csv) {
  std::ifstream f(csv);
  std::string line;
  std::getline(f, line);  // header
  std::vector<std::vector<double>> rows;
  while (std::getline(f, line)) {
    std::vector<double> v;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) v.push_back(std::stod(cell));
    rows.push_back(v);
  }
  return rows;
}

TEST(ShippedPolicyWorld, WalksTheFirstLegOfTheRoomLoopUpright) {
  const fs::path dir =
      fs::temp_directory_path() / ("penumbra_policy_world_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  WorldConfig world = LoadWorldFile(kPolicyWorld);
  ASSERT_FALSE(world.models.empty());
  ASSERT_EQ(world.models.front().controller.type, "policy");  // robots are composed first
  world.cameras.clear();  // physics and control only: no camera changes them
  RunOptions options;
  options.progress = false;
  options.duration_sec = 4.0;
  options.out_dir = (dir / "run").string();
  RunWorld(world, options);

  const std::vector<std::vector<double>> rows =
      ReadPolicyTrajectory(dir / "run" / "trajectory.csv");
  ASSERT_GT(rows.size(), 100u);
  // qpos of the free joint: x y z, then the quaternion w x y z
  double path_m = 0, min_z = 1e9, max_tilt_deg = 0;
  for (size_t i = 0; i < rows.size(); ++i) {
    const std::vector<double>& r = rows[i];
    ASSERT_GE(r.size(), 9u);
    if (i > 0) path_m += std::hypot(r[2] - rows[i - 1][2], r[3] - rows[i - 1][3]);
    min_z = std::min(min_z, r[4]);
    // angle between the trunk's z axis and the world's: cos = 1 - 2 (qx^2 + qy^2)
    const double cos_tilt = 1 - 2 * (r[6] * r[6] + r[7] * r[7]);
    max_tilt_deg = std::max(max_tilt_deg, std::acos(std::clamp(cos_tilt, -1.0, 1.0)) * 180 / M_PI);
  }
  const double dx = rows.back()[2] - (-0.2), dy = rows.back()[3] - (-1.45);
  // 0.45 m/s commanded towards the first waypoint (1.3, -1.0), 1.57 m away: after 4 s the
  // robot has walked most of the way there (the policy tracks 0.5 m/s within 11 %)
  EXPECT_GT(path_m, 1.0) << "walked " << path_m << " m";
  EXPECT_GT(std::hypot(dx, dy), 0.9);
  EXPECT_GT(dx, 0.8) << "first leg heads +x";
  EXPECT_GT(min_z, 0.2) << "trunk stays up (the crawler of the first training run failed this)";
  EXPECT_LT(max_tilt_deg, 30) << "upright";
  fs::remove_all(dir);
}

}  // namespace
}  // namespace penumbra
