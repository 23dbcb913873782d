// world-file `sensors:`: parsing, robot prefixes, and ConfigErrors naming sensor and key.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "penumbra/core/error.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

class SensorsReaderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("penumbra_sensors_reader_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    std::ofstream(dir_ / "m.xml") << "<mujoco><worldbody><body name=\"b\"><freejoint/>"
                                     "<geom size=\"0.1\"/></body></worldbody></mujoco>";
  }
  void TearDown() override { fs::remove_all(dir_); }
  WorldConfig Parse(const std::string& text) {
    return ParseWorld("robots:\n  - name: r\n    file: m.xml\n" + text,
                      (dir_ / "world.yaml").string());
  }
  // the ConfigError message for `text`, or "" if it parses
  std::string Error(const std::string& text) {
    try {
      Parse(text);
    } catch (const ConfigError& e) {
      return e.what();
    }
    return "";
  }
  fs::path dir_;
};

TEST_F(SensorsReaderTest, ParsesTopLevelAndRobotSensors) {
  const WorldConfig w = Parse(R"(    sensors:
      - {name: imu, type: imu, body: b, preset: tactical, rate_hz: 400,
         noise: {gyro_noise_density: 1.0e-4}}
sensors:
  - name: top
    type: lidar
    preset: ouster_os1_128
    body: r/b
    pose: {xyz: [0.1, 0, 0.2], rpy_deg: [0, 0, 90]}
    rate_hz: 20
    latency_sec: 0.1
    columns: 1024
    media: false
    noise: {range_stddev_m: 0.02, dropout_probability: 0.05}
  - {name: all, type: mujoco}
  - {name: gt, type: ground_truth, bodies: [r/b], contacts: false}
)");
  ASSERT_EQ(w.sensors.size(), 4u);
  const SensorConfig& l = w.sensors[0];
  EXPECT_EQ(l.name, "top");
  EXPECT_EQ(l.kind(), SensorKind::kLidar);
  EXPECT_EQ(l.body, "r/b");
  ASSERT_NE(l.get<LidarSensorParams>(), nullptr);
  const LidarSensorParams& lp = *l.get<LidarSensorParams>();
  EXPECT_EQ(lp.preset, "ouster_os1_128");
  EXPECT_EQ(*l.rate_hz, 20);
  EXPECT_EQ(l.latency_sec, 0.1);
  EXPECT_EQ(lp.columns, 1024);
  EXPECT_FALSE(lp.media);
  EXPECT_EQ(lp.range_stddev_m, 0.02);
  EXPECT_EQ(lp.dropout_probability, 0.05);
  EXPECT_FALSE(lp.beam_divergence_mrad);  // not given: the preset's
  EXPECT_NEAR(l.X_AS().translation().z(), 0.2, 1e-12);
  EXPECT_EQ(l.key, "sensors[0]");
  EXPECT_EQ(w.sensors[1].kind(), SensorKind::kMujoco);
  EXPECT_FALSE(w.sensors[1].rate_hz);
  ASSERT_NE(w.sensors[2].get<GroundTruthSensorParams>(), nullptr);
  EXPECT_FALSE(w.sensors[2].get<GroundTruthSensorParams>()->contacts);
  EXPECT_EQ(w.sensors[2].get<GroundTruthSensorParams>()->bodies, std::vector<std::string>{"r/b"});
  const SensorConfig& imu = w.sensors[3];  // robot sensors come after the top-level list
  EXPECT_EQ(imu.robot, "r");
  EXPECT_EQ(imu.body, "r/b");  // prefixed with the robot name
  EXPECT_EQ(imu.key, "robots[0].sensors[0]");
  ASSERT_NE(imu.get<ImuSensorParams>(), nullptr);
  EXPECT_EQ(imu.get<ImuSensorParams>()->preset, "tactical");
  EXPECT_EQ(imu.get<ImuSensorParams>()->gyro_noise_density, 1e-4);
  EXPECT_FALSE(imu.get<ImuSensorParams>()->accel_noise_density);  // not given: the preset's
  // the model's noise: the preset with the override
  EXPECT_EQ(imu.get<ImuSensorParams>()->MakeNoise().gyro_noise_density, 1e-4);
  EXPECT_EQ(imu.get<ImuSensorParams>()->MakeNoise().accel_noise_density,
            ImuPreset("tactical").accel_noise_density);
}

TEST_F(SensorsReaderTest, InvalidSettingsNameSensorAndKey) {
  struct Case {
    std::string yaml, key, what;
  };
  const Case cases[] = {
      {"sensors:\n  - {name: s, type: lidar, preset: velodyne_vlp16, rate_hz: 0}\n",
       "sensors[0].rate_hz", "expected a rate > 0"},
      {"sensors:\n  - {name: s, type: lidar, preset: hdl64}\n", "sensors[0].preset",
       "unknown value 'hdl64'"},
      {"sensors:\n  - {name: s, type: imu, body: r/b, preset: nav}\n", "sensors[0].preset",
       "unknown value 'nav'"},
      {"sensors:\n  - {name: s, type: lidar, preset: velodyne_vlp16, noise: {range_stddev_m: "
       "-1}}\n",
       "sensors[0].noise.range_stddev_m", "expected a noise value >= 0"},
      {"sensors:\n  - {name: s, type: imu, body: r/b, noise: {accel_random_walk: -0.1}}\n",
       "sensors[0].noise.accel_random_walk", ">= 0"},
      {"sensors:\n  - {name: s, type: imu}\n", "sensors[0]", "needs 'body' or 'site'"},
      {"sensors:\n  - {name: s, type: imu, body: r/b, site: x}\n", "sensors[0].site",
       "both body and site"},
      {"sensors:\n  - {name: s, type: imu, body: r/b, latency_sec: -1}\n", "sensors[0].latency_sec",
       "expected a number in [0, 3600]"},
      {"sensors:\n  - {name: s, type: sonar}\n", "sensors[0].type", "unknown value 'sonar'"},
      {"sensors:\n  - {name: s, type: mujoco, preset: x}\n", "sensors[0].preset", "unknown key"},
      {"sensors:\n  - {name: s, type: mujoco}\n  - {name: s, type: ground_truth}\n",
       "sensors[1].name", "used twice"},
      {"    sensors:\n      - {name: s, type: lidar, preset: velodyne_vlp16, rate_hz: -5}\n",
       "robots[0].sensors[0].rate_hz", "expected a rate > 0"},
  };
  for (const Case& c : cases) {
    const std::string msg = Error(c.yaml);
    EXPECT_NE(msg.find(c.key), std::string::npos) << c.yaml << " -> " << msg;
    EXPECT_NE(msg.find(c.what), std::string::npos) << c.yaml << " -> " << msg;
    EXPECT_NE(msg.find("'s'"), std::string::npos) << "names the sensor: " << msg;
  }
}

}  // namespace
}  // namespace penumbra
