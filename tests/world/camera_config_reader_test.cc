// world-file keys of camera sensors and semantic classes: values parse, and bad values give a
// ConfigError naming the file, line, key path and the camera.

#include "penumbra/world/camera_config_reader.h"

#include <gtest/gtest.h>

#include <string>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

constexpr const char* kCameras = R"(
cameras:
  - name: front
    width: 320
    height: 240
    fovy_deg: 50
    outputs: [rgb, depth, range, normals, instance_segmentation, semantic_segmentation]
    distortion: {k1: -0.28, k2: 0.07, p1: 0.001, p2: -0.0005, k3: -0.01}
    exposure_time_sec: 0.02
    motion_blur_samples: 5
    rolling_shutter_line_time_sec: 2.0e-5
    auto_exposure_time_constant_sec: 0.3
    noise: {full_well_e: 6000, read_noise_e: 2.5, iso: 800, adc_bits: 10}
    jpeg_quality: 85
    lens_droplets: {count: 4}
    white_balance: 3200
    depth_noise: {preset: realsense_d435, max_range_m: 6}
    stereo: {baseline_m: 0.12}
semantic_classes:
  - {name: robot, id: 1, bodies: ["rover/*"]}
  - {name: floor, id: 7, geoms: [floor], materials: ["*concrete*"]}
)";

TEST(CameraConfigReaderTest, SensorKeysAndClassesParse) {
  const WorldConfig w = ParseWorld(kCameras, "w.yaml");
  ASSERT_EQ(w.cameras.size(), 1u);
  const CameraConfig& c = w.cameras[0];
  EXPECT_EQ(c.k1, -0.28);
  EXPECT_EQ(c.k2, 0.07);
  EXPECT_EQ(c.p1, 0.001);
  EXPECT_EQ(c.p2, -0.0005);
  EXPECT_EQ(c.k3, -0.01);
  EXPECT_TRUE(c.outputs[ImageKind::kRange] && c.outputs[ImageKind::kNormals] &&
              c.outputs[ImageKind::kInstanceSegmentation] &&
              c.outputs[ImageKind::kSemanticSegmentation] && !c.outputs[ImageKind::kSegmentation]);
  const CameraSensorConfig& s = c.sensor;
  EXPECT_EQ(s.exposure_time_sec, 0.02);
  EXPECT_EQ(s.motion_blur_samples, 5);
  EXPECT_EQ(s.rolling_shutter_line_time_sec, 2e-5);
  EXPECT_EQ(s.auto_exposure_time_constant_sec, 0.3);
  EXPECT_TRUE(s.noise.enabled);
  EXPECT_EQ(s.noise.full_well_e, 6000);
  EXPECT_EQ(s.noise.read_noise_e, 2.5);
  EXPECT_EQ(s.noise.iso, 800);
  EXPECT_EQ(s.noise.adc_bits, 10);
  EXPECT_EQ(s.jpeg_quality, 85);
  EXPECT_EQ(s.lens_droplet_count, 4);
  EXPECT_EQ(s.white_balance.mode, WhiteBalance::Mode::kKelvin);
  EXPECT_EQ(s.white_balance.kelvin, 3200);
  EXPECT_EQ(s.depth_noise.preset, "realsense_d435");
  EXPECT_EQ(*s.depth_noise.max_range_m, 6);
  EXPECT_EQ(*s.stereo_baseline_m, 0.12);
  ASSERT_EQ(w.semantic_classes.size(), 2u);
  EXPECT_EQ(w.semantic_classes[0].name, "robot");
  EXPECT_EQ(w.semantic_classes[0].bodies[0], "rover/*");
  EXPECT_EQ(w.semantic_classes[1].id, 7);
  EXPECT_EQ(w.semantic_classes[1].materials[0], "*concrete*");
}

// the ConfigError of parsing `camera_body` (keys of one camera named "cam").
ConfigError ErrorOf(const std::string& camera_body) {
  try {
    ParseWorld("cameras:\n  - name: cam\n" + camera_body, "w.yaml");
  } catch (const ConfigError& e) {
    return e;
  }
  ADD_FAILURE() << "no ConfigError for:\n" << camera_body;
  return ConfigError("", 0, "", "");
}

TEST(CameraConfigReaderTest, BadValuesNameCameraAndKey) {
  struct Case {
    const char* yaml;
    const char* key;
  };
  const Case cases[] = {
      // 90 deg vertical fov: the image corners lie beyond the radius where the lens folds
      {"    fovy_deg: 90\n    distortion: {k1: -0.28, k2: 0.07, k3: -0.01}\n",
       "cameras[0].distortion"},
      {"    distortion: {k1: -0.9}\n", "cameras[0].distortion"},
      {"    exposure_time_sec: -0.01\n", "cameras[0].exposure_time_sec"},
      {"    motion_blur_samples: 0\n", "cameras[0].motion_blur_samples"},
      {"    rolling_shutter_line_time_sec: -1\n", "cameras[0].rolling_shutter_line_time_sec"},
      {"    noise: {full_well_e: 0}\n", "cameras[0].noise.full_well_e"},
      {"    noise: {adc_bits: 17}\n", "cameras[0].noise.adc_bits"},
      {"    jpeg_quality: 101\n", "cameras[0].jpeg_quality"},
      {"    white_balance: 1000\n", "cameras[0].white_balance"},
      {"    white_balance: sunny\n", "cameras[0].white_balance"},
      {"    depth_noise: {preset: kinect_v3}\n", "cameras[0].depth_noise.preset"},
      {"    stereo: {baseline_m: 0}\n", "cameras[0].stereo.baseline_m"},
      {"    distortion: {k4: 0.1}\n", "cameras[0].distortion.k4"},
  };
  for (const Case& c : cases) {
    const ConfigError e = ErrorOf(c.yaml);
    EXPECT_EQ(e.file(), "w.yaml") << c.yaml;
    EXPECT_GT(e.line(), 1) << c.yaml;
    EXPECT_EQ(e.key(), c.key) << c.yaml << e.what();
    const std::string what = e.what();
    if (std::string(c.key).find("k4") == std::string::npos) {
      EXPECT_NE(what.find("camera 'cam'"), std::string::npos) << what;
    }
  }
}

TEST(CameraConfigReaderTest, MjcfCameraOverridesTakeSensorKeysButNotStereo) {
  const std::string models = std::string("robots:\n  - {name: rover, file: ") +
                             PENUMBRA_SOURCE_DIR + "/worlds/models/rover.xml}\n";
  const WorldConfig w = ParseWorld(models +
                                       "mjcf_cameras:\n  overrides:\n    rover/head:\n"
                                       "      distortion: {k1: -0.1}\n"
                                       "      motion_blur_samples: 3\n      noise: {iso: 200}\n",
                                   "w.yaml");
  ASSERT_EQ(w.mjcf_cameras.overrides.size(), 1u);
  EXPECT_EQ(w.mjcf_cameras.overrides[0].k1, -0.1);
  EXPECT_EQ(w.mjcf_cameras.overrides[0].sensor.motion_blur_samples, 3);
  EXPECT_TRUE(w.mjcf_cameras.overrides[0].sensor.noise.enabled);
  try {
    ParseWorld(
        models + "mjcf_cameras:\n  overrides:\n    rover/head:\n      stereo: {baseline_m: 0.1}\n",
        "w.yaml");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "mjcf_cameras.overrides.rover/head.stereo");
  }
}

TEST(CameraConfigReaderTest, BadSemanticClassesAreRejected) {
  EXPECT_THROW(ParseWorld("semantic_classes:\n  - {name: a, id: 0, bodies: [x]}\n", "w.yaml"),
               ConfigError);
  EXPECT_THROW(ParseWorld("semantic_classes:\n  - {name: a, id: 1, bodies: [x]}\n  - {name: b, id: "
                          "1, geoms: [y]}\n",
                          "w.yaml"),
               ConfigError);
  EXPECT_THROW(ParseWorld("semantic_classes:\n  - {name: a, id: 1}\n", "w.yaml"), ConfigError);
}

}  // namespace
}  // namespace penumbra
