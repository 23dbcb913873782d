// world-file `profile:` of cameras and mjcf_cameras (world/camera_config_reader.h): a profile's
// values, explicit keys over them, unknown names refused with the key and the names, and every
// bundled world's cameras naming one.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "penumbra/core/error.h"
#include "penumbra/sensors/camera_imager.h"
#include "penumbra/sensors/camera_profile.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

std::string WorldWithCamera(const std::string& extra) {
  return "cameras:\n  - name: front\n    width: 160\n    height: 120\n" + extra;
}

TEST(CameraProfileKeys, AProfileSetsItsValuesAndExplicitKeysOverrideThem) {
  const WorldConfig w = ParseWorld(WorldWithCamera("    profile: realsense_d435_rgb\n"), "w.yaml");
  ASSERT_EQ(w.cameras.size(), 1u);
  const CameraSensorConfig& s = w.cameras[0].sensor;
  const CameraSensorConfig p = CameraProfileConfig(CameraProfile::kRealsenseD435Rgb);
  EXPECT_EQ(s.profile, CameraProfile::kRealsenseD435Rgb);
  EXPECT_TRUE(s.noise.enabled);
  EXPECT_EQ(s.noise.full_well_e, p.noise.full_well_e);
  EXPECT_EQ(s.auto_exposure.max_gain, p.auto_exposure.max_gain);
  // the profile's readout over the camera's 120 rows
  EXPECT_NEAR(RowTimeSec(s, 120), p.rolling_shutter_readout_sec / 120, 1e-15);

  const WorldConfig o = ParseWorld(WorldWithCamera("    profile: realsense_d435_rgb\n"
                                                   "    noise: {read_noise_e: 7}\n"
                                                   "    rolling_shutter_line_time_sec: 0\n"
                                                   "    auto_exposure: {max_gain: 2}\n"
                                                   "    optics: {vignetting_exponent: 0}\n"),
                                   "w.yaml");
  const CameraSensorConfig& so = o.cameras[0].sensor;
  EXPECT_EQ(so.noise.read_noise_e, 7);
  EXPECT_EQ(so.noise.full_well_e, p.noise.full_well_e);  // the rest stays the profile's
  EXPECT_EQ(RowTimeSec(so, 120), 0);                     // global shutter now
  EXPECT_EQ(so.auto_exposure.max_gain, 2);
  EXPECT_EQ(so.auto_exposure.max_exposure_time_sec, p.auto_exposure.max_exposure_time_sec);
  EXPECT_EQ(so.optics.vignetting_exponent, 0);
  EXPECT_EQ(so.optics.psf_sigma_px, p.optics.psf_sigma_px);
}

TEST(CameraProfileKeys, NoProfileAndIdealAreTheCleanCamera) {
  const WorldConfig none = ParseWorld(WorldWithCamera(""), "w.yaml");
  const WorldConfig ideal = ParseWorld(WorldWithCamera("    profile: ideal\n"), "w.yaml");
  for (const WorldConfig* w : {&none, &ideal}) {
    const CameraSensorConfig& s = w->cameras[0].sensor;
    EXPECT_EQ(s.profile, CameraProfile::kIdeal);
    EXPECT_FALSE(s.noise.enabled);
    EXPECT_FALSE(s.auto_exposure.enabled);
    EXPECT_EQ(s.optics.vignetting_exponent, 0);
    EXPECT_EQ(RowTimeSec(s, 120), 0);
  }
}

TEST(CameraProfileKeys, UnknownNamesAreRefusedWithTheKeyAndTheNames) {
  for (const std::string& yaml : {WorldWithCamera("    profile: realsense_d455\n"),
                                  std::string("mjcf_cameras: {enabled: true, profile: nope}\n")}) {
    try {
      ParseWorld(yaml, "w.yaml");
      ADD_FAILURE() << "no ConfigError for " << yaml;
    } catch (const ConfigError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("profile"), std::string::npos) << m;
      EXPECT_NE(m.find("ideal, realsense_d435_rgb, blackfly_s_imx250"), std::string::npos) << m;
    }
  }
  try {
    ParseWorld(WorldWithCamera("    auto_exposure: {max_gain: 0.5}\n"), "w.yaml");
    ADD_FAILURE();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("max_gain"), std::string::npos) << e.what();
  }
}

TEST(CameraProfileKeys, MjcfCamerasTakeTheirBlocksProfile) {
  const WorldConfig w = ParseWorld(
      "models:\n  - {name: arm, file: models/table_scene.xml}\n"
      "mjcf_cameras:\n  enabled: true\n  profile: blackfly_s_imx250\n"
      "  overrides:\n    arm/wrist: {width: 64, height: 48}\n",
      std::string(PENUMBRA_SOURCE_DIR) + "/worlds/w.yaml");
  EXPECT_EQ(w.mjcf_cameras.profile, CameraProfile::kBlackflySImx250);
  ASSERT_EQ(w.mjcf_cameras.overrides.size(), 1u);
  EXPECT_EQ(w.mjcf_cameras.overrides[0].sensor.profile, CameraProfile::kBlackflySImx250);
  EXPECT_TRUE(w.mjcf_cameras.overrides[0].sensor.noise.enabled);
}

// every camera of every bundled world and benchmark names its profile: a real camera unless it
// says `profile: ideal`
TEST(CameraProfileKeys, EveryBundledCameraNamesAProfile) {
  namespace fs = std::filesystem;
  const fs::path root(PENUMBRA_SOURCE_DIR);
  int files = 0;
  for (const char* dir : {"worlds", "benchmarks"}) {
    for (const auto& e : fs::recursive_directory_iterator(root / dir)) {
      if (!e.is_regular_file() || e.path().extension() != ".yaml") continue;
      std::ifstream in(e.path());
      std::stringstream text;
      text << in.rdbuf();
      const std::string s = text.str();
      if (s.find("cameras:") == std::string::npos && s.find("camera: {") == std::string::npos)
        continue;
      SCOPED_TRACE(e.path().string());
      ++files;
      if (std::string(dir) == "worlds") {
        const WorldConfig w = LoadWorldFile(e.path().string());
        for (const CameraConfig& c : w.cameras)
          EXPECT_NE(s.find("profile: " + std::string(CameraProfileName(c.sensor.profile))),
                    std::string::npos)
              << c.name;
        for (const CameraConfig& c : w.cameras) EXPECT_TRUE(c.sensor.noise.enabled) << c.name;
        if (w.mjcf_cameras.enabled && s.find("mjcf_cameras:") != std::string::npos &&
            s.find("mjcf_cameras: {enabled: false}") == std::string::npos)
          EXPECT_NE(w.mjcf_cameras.profile, CameraProfile::kIdeal);
      } else {
        // benchmark cameras: one `profile:` per `camera:` entry
        auto count = [&](const std::string& what) {
          int n = 0;
          for (size_t at = s.find(what); at != std::string::npos; at = s.find(what, at + 1)) ++n;
          return n;
        };
        const int cams = count("camera: {"), profiles = count("profile: realsense_d435_rgb");
        EXPECT_EQ(cams, profiles);
      }
    }
  }
  EXPECT_GE(files, 30);
}

}  // namespace
}  // namespace penumbra
