// the sensor registry (sensors/sensor_types.h): one entry per type in SensorKind order, the
// types' facts, and their models built from the parameters.
#include "penumbra/sensors/sensor_types.h"

#include <gtest/gtest.h>

#include <set>
#include <string>

#include "penumbra/sensors/imu_model.h"
#include "penumbra/sensors/lidar_pattern.h"

namespace penumbra {
namespace {

TEST(SensorTypes, RegistryListsEveryTypeOnceInKindOrder) {
  ASSERT_EQ(kSensorKindCount, 4);
  std::set<std::string_view> names, folders;
  for (int i = 0; i < kSensorKindCount; ++i) {
    const SensorTypeInfo& t = kSensorTypes[i];
    EXPECT_EQ(static_cast<int>(t.kind), i);
    EXPECT_TRUE(names.insert(t.name).second) << t.name;
    EXPECT_TRUE(folders.insert(t.output_folder).second) << t.output_folder;
    EXPECT_EQ(SensorKindFromName(t.name), t.kind);
    EXPECT_EQ(KindOf(DefaultSensorParams(t.kind)), t.kind);
  }
  EXPECT_FALSE(SensorKindFromName("depth"));
}

TEST(SensorTypes, NamesFoldersAndRatesOfTheWorldFileAndRunFolders) {
  // the world file's `type:` and the run folders of docs/sensors.md
  EXPECT_EQ(SensorKindName(SensorKind::kLidar), "lidar");
  EXPECT_EQ(SensorKindName(SensorKind::kImu), "imu");
  EXPECT_EQ(SensorKindName(SensorKind::kMujoco), "mujoco");
  EXPECT_EQ(SensorKindName(SensorKind::kGroundTruth), "ground_truth");
  EXPECT_EQ(Info(SensorKind::kLidar).output_folder, "lidar");
  EXPECT_EQ(Info(SensorKind::kImu).output_folder, "imu");
  EXPECT_EQ(Info(SensorKind::kMujoco).output_folder, "sensors");
  EXPECT_EQ(Info(SensorKind::kGroundTruth).output_folder, "ground_truth");
  EXPECT_EQ(Info(SensorKind::kImu).default_rate_hz, 200.0);
  EXPECT_EQ(Info(SensorKind::kMujoco).default_rate_hz, 100.0);
  EXPECT_TRUE(Info(SensorKind::kLidar).rate_from_model);
  EXPECT_FALSE(Info(SensorKind::kImu).rate_from_model);
  EXPECT_EQ(Info(SensorKind::kImu).attach, SensorAttach::kRequired);
  EXPECT_EQ(Info(SensorKind::kLidar).attach, SensorAttach::kDefaultWorld);
  EXPECT_EQ(Info(SensorKind::kGroundTruth).attach, SensorAttach::kNone);
}

TEST(SensorTypes, LidarParamsMakeThePresetPatternWithOverrides) {
  LidarSensorParams p;
  p.preset = "ouster_os1_64";
  const LidarConfig plain = p.MakeConfig(0);
  const LidarPattern preset = MakeLidarPattern("ouster_os1_64");
  EXPECT_EQ(plain.pattern.beams.size(), preset.beams.size());
  EXPECT_EQ(plain.pattern.rate_hz, preset.rate_hz);
  EXPECT_EQ(plain.pattern.beam_divergence_rad, preset.beam_divergence_rad);
  EXPECT_TRUE(plain.media);
  p.columns = 512;
  p.beam_divergence_mrad = 2.0;
  p.range_stddev_m = 0.03;
  p.media = false;
  const LidarConfig c = p.MakeConfig(20);
  EXPECT_EQ(c.pattern.beams.size(), 64u * 512u);
  EXPECT_EQ(c.pattern.rate_hz, 20);
  EXPECT_DOUBLE_EQ(c.pattern.beam_divergence_rad, 2e-3);
  EXPECT_EQ(c.range_noise_stddev_m, 0.03);
  EXPECT_FALSE(c.media);
}

TEST(SensorTypes, ImuParamsOverrideOnlyTheGivenNoiseValues) {
  ImuSensorParams p;
  p.preset = "tactical";
  p.gyro_random_walk = 1e-3;
  const ImuNoiseConfig n = p.MakeNoise();
  const ImuNoiseConfig t = ImuPreset("tactical");
  EXPECT_EQ(n.gyro_random_walk, 1e-3);
  EXPECT_EQ(n.gyro_noise_density, t.gyro_noise_density);
  EXPECT_EQ(n.accel_noise_density, t.accel_noise_density);
  EXPECT_EQ(n.accel_random_walk, t.accel_random_walk);
}

}  // namespace
}  // namespace penumbra
