// end-to-end sensors: world file `sensors:` -> composed IMU sensors -> SensorSink -> PCD and
// CSV files; post-composition errors name the sensor and key.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "common/temp_dir.h"
#include "penumbra/run/runner.h"
#include "penumbra/core/error.h"
#include "penumbra/output/pcd_writer.h"
#include "penumbra/sensors/imu_model.h"
#include "penumbra/sensors/lidar_pattern.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

// a box resting on the floor, a ball falling from 20 m (no contact within 1 s), walls.
constexpr char kModel[] = R"(
<mujoco model="drop">
  <option timestep="0.002"/>
  <worldbody>
    <geom name="floor" type="plane" size="10 10 0.1"/>
    <geom name="wall" type="box" pos="5 0 1" size="0.1 5 1"/>
    <body name="box" pos="0 0 0.1">
      <freejoint/>
      <geom name="box" type="box" size="0.1 0.1 0.1" mass="1"/>
      <site name="imu_site" pos="0 0 0.05"/>
      <site name="pad" type="box" size="0.11 0.11 0.02" pos="0 0 -0.1"/>
    </body>
    <body name="ball" pos="0 3 20">
      <freejoint/>
      <geom name="ball" type="sphere" size="0.1" mass="1"/>
    </body>
  </worldbody>
  <sensor><touch name="box_touch" site="pad"/></sensor>
</mujoco>)";

class SensorRunTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("penumbra_sensor_run_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    std::ofstream(dir_ / "drop.xml") << kModel;
  }
  void TearDown() override { fs::remove_all(dir_); }

  WorldConfig World(const std::string& sensors) {
    std::ofstream(dir_ / "world.yaml")
        << "duration_sec: 1\nmjcf_cameras: {enabled: false}\nrobots:\n"
           "  - name: m\n    file: drop.xml\n"
        << sensors;
    return LoadWorldFile((dir_ / "world.yaml").string());
  }
  static std::vector<std::vector<std::string>> Csv(const fs::path& p) {
    std::ifstream f(p);
    std::vector<std::vector<std::string>> rows;
    std::string line;
    while (std::getline(f, line)) {
      std::vector<std::string> row;
      std::stringstream ss(line);
      std::string cell;
      while (std::getline(ss, cell, ',')) row.push_back(cell);
      rows.push_back(row);
    }
    return rows;
  }
  fs::path dir_;
};

TEST_F(SensorRunTest, WritesScansImuMujocoAndGroundTruth) {
  const WorldConfig world = World(R"(    sensors:
      - {name: rest_imu, type: imu, site: imu_site, preset: ideal, rate_hz: 200, latency_sec: 0.01}
      - {name: fall_imu, type: imu, body: ball, preset: ideal, rate_hz: 200}
      - {name: rot_imu, type: imu, site: imu_site, pose: {rpy_deg: [90, 0, 0]}, preset: ideal}
sensors:
  - name: lidar
    type: lidar
    preset: velodyne_vlp16
    body: world
    pose: {xyz: [0, 0, 1], rpy_deg: [0, 0, 0]}
  - {name: touch, type: mujoco, sensors: [m/box_touch], rate_hz: 50}
  - {name: truth, type: ground_truth, bodies: [m/box, m/ball], rate_hz: 10}
)");
  RunOptions opt;
  opt.out_dir = (dir_ / "out").string();
  opt.progress = false;
  RunWorld(world, opt);
  const fs::path out = dir_ / "out";
  // lidar: scans 0..9 (scan 10 at t = 1 s is still open at the end)
  const auto index = Csv(out / "lidar" / "lidar" / "index.csv");
  ASSERT_EQ(index.size(), 11u);
  EXPECT_EQ(index[0][0], "scan");
  const std::vector<LidarPoint> pts =
      ReadPcd((out / "lidar" / "lidar" / "scan_000003.pcd").string());
  EXPECT_EQ(std::to_string(pts.size()), index[4][4]);
  // the wall at x = 4.9 (front face) is seen straight ahead by the horizontal-most rings
  int wall = 0;
  for (const LidarPoint& p : pts)
    if (std::abs(p.x - 4.9) < 1e-3 && std::abs(p.y) < 0.5 && p.z > -1 && p.z < 1) ++wall;
  EXPECT_GT(wall, 10);
  // imu: 200 Hz over [0, 1] s = 201 samples; resting one reads +g up, falling one ~0
  const auto rest = Csv(out / "imu" / "rest_imu.csv");
  const auto fall = Csv(out / "imu" / "fall_imu.csv");
  ASSERT_EQ(rest.size(), 202u);
  ASSERT_EQ(fall.size(), 202u);
  EXPECT_EQ(rest[0][3], "accel_x_m_s2");
  EXPECT_NEAR(std::stod(rest[150][2]) - std::stod(rest[150][1]), 0.01, 1e-9);  // latency
  EXPECT_NEAR(std::stod(rest[150][5]), 9.81, 0.01);
  for (int k = 1; k <= 3; ++k) EXPECT_LT(std::abs(std::stod(fall[150][2 + k])), 1e-6);
  // rolled 90 deg about x relative to the site: world up is the IMU's +y
  const auto rot = Csv(out / "imu" / "rot_imu.csv");
  ASSERT_GT(rot.size(), 150u);
  EXPECT_NEAR(std::stod(rot[150][4]), 9.81, 0.01);
  EXPECT_NEAR(std::stod(rot[150][5]), 0.0, 0.01);
  // mujoco touch: 50 Hz, weight of the 1 kg box
  const auto touch = Csv(out / "sensors" / "touch.csv");
  ASSERT_EQ(touch.size(), 52u);
  EXPECT_EQ(touch[0][3], "m/box_touch_N");
  EXPECT_NEAR(std::stod(touch[40][3]), 9.81, 0.05);
  // ground truth: ball falls freely: z = 20 - g t^2 / 2, vz = -g t
  const auto truth = Csv(out / "ground_truth" / "truth.csv");
  ASSERT_EQ(truth.size(), 12u);
  EXPECT_EQ(truth[0][2 + 13 + 2], "m/ball_z_m");
  const double t = std::stod(truth[11][1]);
  EXPECT_NEAR(std::stod(truth[11][2 + 13 + 2]), 20 - 0.5 * 9.81 * t * t, 0.01);
  EXPECT_NEAR(std::stod(truth[11][2 + 13 + 12]), -9.81 * t, 0.01);
  EXPECT_TRUE(fs::exists(out / "ground_truth" / "truth_contacts.csv"));
}

TEST_F(SensorRunTest, MissingBodyOrSiteNamesTheSensorAndKey) {
  const auto expect_error = [&](const std::string& sensors, const std::string& key) {
    const WorldConfig world = World(sensors);
    RunOptions opt;
    opt.out_dir = (dir_ / "out").string();
    opt.progress = false;
    opt.force = true;  // each failed attempt leaves composed.xml behind
    try {
      RunWorld(world, opt);
      ADD_FAILURE() << "no error for " << key;
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("'bad'"), std::string::npos) << e.what();
    }
  };
  expect_error("sensors:\n  - {name: bad, type: imu, body: m/nobody}\n", "sensors[0].body");
  expect_error("sensors:\n  - {name: bad, type: imu, site: m/nosite}\n", "sensors[0].site");
  expect_error("sensors:\n  - {name: bad, type: lidar, preset: velodyne_vlp16, body: m/nobody}\n",
               "sensors[0].body");
  expect_error(
      "    sensors:\n      - {name: bad, type: lidar, preset: livox_mid40, site: nosite}\n",
      "robots[0].sensors[0].site");
  expect_error("sensors:\n  - {name: bad, type: mujoco, sensors: [m/none]}\n",
               "sensors[0].sensors");
}

TEST_F(SensorRunTest, SameSeedSameBytesAndWorldPresetNamesMatchTheSensorModels) {
  const std::string sensors = R"(sensors:
  - {name: l, type: lidar, preset: ouster_os1_64, body: m/box, pose: {xyz: [0, 0, 0.5]},
     noise: {range_stddev_m: 0.02, dropout_probability: 0.1, receiver_noise: 0.2}}
  - {name: i, type: imu, body: m/ball, preset: consumer_mems}
)";
  std::string first_pcd, first_imu;
  for (int run = 0; run < 2; ++run) {
    const WorldConfig world = World(sensors);
    RunOptions opt;
    opt.out_dir = (dir_ / ("out" + std::to_string(run))).string();
    opt.progress = false;
    opt.duration_sec = 0.3;
    RunWorld(world, opt);
    const std::string pcd =
        testing::ReadAll(fs::path(opt.out_dir) / "lidar" / "l" / "scan_000001.pcd");
    const std::string imu = testing::ReadAll(fs::path(opt.out_dir) / "imu" / "i.csv");
    if (run == 0) {
      first_pcd = pcd;
      first_imu = imu;
      EXPECT_GT(first_pcd.size(), 1000u);
    } else {
      EXPECT_TRUE(pcd == first_pcd);
      EXPECT_TRUE(imu == first_imu);
    }
  }
  // every preset the world file accepts builds in the sensor models
  for (const std::string& p : LidarPresetNames()) {
    EXPECT_NO_THROW(World("sensors:\n  - {name: x, type: lidar, preset: " + p + "}\n")) << p;
    EXPECT_NO_THROW(MakeLidarPattern(p)) << p;
  }
  for (const std::string& p : ImuPresetNames()) {
    EXPECT_NO_THROW(World("sensors:\n  - {name: x, type: imu, body: m/box, preset: " + p + "}\n"))
        << p;
    EXPECT_NO_THROW(ImuPreset(p)) << p;
  }
}

}  // namespace
}  // namespace penumbra
