// tests of the world-file loader: a complete file parses into the expected values,
// and every class of bad input gives a ConfigError that names the file, the line,
// the key path and what was expected.

#include "penumbra/world/world_config.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "penumbra/config/yaml_document.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

constexpr const char* kMinimalMjcf =
    R"(<mujoco><worldbody><body name="chassis"><geom type="box" size="0.1 0.1 0.1"/></body></worldbody></mujoco>)";

// a scratch folder with model files, removed after each test.
class WorldConfigTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("penumbra_world_test_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "models");
    WriteFile(dir_ / "models" / "rover.xml", kMinimalMjcf);
    WriteFile(dir_ / "models" / "room.xml", kMinimalMjcf);
    WriteFile(dir_ / "models" / "arm.urdf", "<robot name=\"arm\"><link name=\"base\"/></robot>");
    world_ = (dir_ / "world.yaml").string();
  }
  void TearDown() override { fs::remove_all(dir_); }

  static void WriteFile(const fs::path& p, const std::string& text) {
    std::ofstream out(p, std::ios::binary);
    out << text;
  }

  // parses `yaml` as if it were `world_` and expects a ConfigError at `line` for
  // `key` whose message also contains `expected`.
  void ExpectError(const std::string& yaml, int line, const std::string& key,
                   const std::string& expected) {
    try {
      ParseWorld(yaml, world_);
      ADD_FAILURE() << "no ConfigError for:\n" << yaml;
    } catch (const ConfigError& e) {
      const std::string what = e.what();
      EXPECT_EQ(e.file(), world_) << what;
      EXPECT_EQ(e.line(), line) << what;
      EXPECT_EQ(e.key(), key) << what;
      std::string prefix = world_ + ":" + std::to_string(line);
      if (!key.empty()) prefix += ": " + key;
      EXPECT_EQ(what.rfind(prefix + ": ", 0), 0u)
          << "message should start with '" << prefix << ": ', got: " << what;
      EXPECT_NE(what.find(expected), std::string::npos)
          << "message should contain '" << expected << "', got: " << what;
    }
  }

  std::string Abs(const std::string& rel) const { return (dir_ / rel).lexically_normal().string(); }

  fs::path dir_;
  std::string world_;
};

// every key of the schema, with non-default values.
constexpr const char* kFullWorld = R"(seed: 7
duration_sec: 20
physics: {timestep_sec: 0.002}
render:
  tier: pathtraced
  samples_per_pixel: 64
  max_bounces: 6
  denoise: false
  threads: 3
  max_anisotropy: 4
  exposure: {mode: manual, ev100: 12.5, compensation_ev: -1}
  tone_map: linear
sky:
  type: daylight
  color: [0.5, 0.6, 0.7]
  luminance_cd_m2: 500
  turbidity: 2.5
  sun_elevation_deg: 30
  sun_azimuth_deg: -45
  zenith_luminance_cd_m2: 6000
robots:
  - name: rover
    file: models/rover.xml
    pose: {xyz: [0, 0, 0.05], rpy_deg: [0, 0, 90]}
    controller:
      type: waypoint_follower
      speed_m_s: 0.5
      waypoints: [[1, 0], [1, 1]]
  - name: arm
    file: models/arm.urdf
models:
  - {name: room, file: models/room.xml}
lights:
  - name: sun
    type: sun
    direction: [0, 0, -2]
    color: [1, 0.9, 0.8]
    illuminance_lux: 20000
    angular_diameter_deg: 1
    cast_shadow: false
  - name: lamp
    type: point
    attach: rover/chassis
    position: [0, 0, 3]
    power_w: 8
    radius_m: 0.05
  - name: torch
    type: spot
    position: [1, 2, 3]
    direction: [0.3, 0, 0]
    intensity_cd: 500
    inner_angle_deg: 20
    outer_angle_deg: 35
  - name: fill
    type: directional
    direction: [1, 0, 0]
    illuminance_lux: 100
cameras:
  - name: front
    attach: rover/chassis
    pose: {xyz: [0.2, 0, 0.1], rpy_deg: [0, 10, 0]}
    width: 320
    height: 240
    fovy_deg: 70
    rate_hz: 15
    outputs: [rgb, depth, segmentation]
  - name: calibrated
    width: 1280
    height: 720
    intrinsics: {fx: 900, fy: 910, cx: 640.5, cy: 360.5}
    outputs: [depth]
mjcf_cameras:
  enabled: false
  width: 800
  height: 600
  rate_hz: 5
  outputs: [rgb, segmentation]
  overrides:
    rover/head: {width: 320, height: 240, rate_hz: 30, outputs: [rgb, depth], fovy_deg: 70, near_m: 0.05}
    room/corner: {intrinsics: {fx: 500, fy: 500}}
materials:
  room/floor: {base_color: [0.5, 0.4, 0.3], roughness: 0.6, metallic: 0, specular: 0.25, emission: [1, 2, 3]}
  rover/paint: {metallic: 1}
output: {dir: results}
)";

TEST_F(WorldConfigTest, FullFileParsesIntoExpectedValues) {
  const WorldConfig w = ParseWorld(kFullWorld, world_);
  EXPECT_EQ(w.file, world_);
  EXPECT_EQ(w.seed, 7u);
  EXPECT_EQ(w.duration_sec, 20);
  ASSERT_TRUE(w.timestep_sec.has_value());
  EXPECT_EQ(*w.timestep_sec, 0.002);
  EXPECT_EQ(w.output_dir, "results");
  EXPECT_FALSE(w.default_lights);

  // render
  EXPECT_EQ(w.render.tier, RenderSettings::Tier::kPathtraced);
  EXPECT_EQ(w.render.samples_per_pixel, 64);
  EXPECT_EQ(w.render.max_bounces, 6);
  EXPECT_FALSE(w.render.denoise);
  EXPECT_EQ(w.render.threads, 3);
  EXPECT_EQ(w.render.max_anisotropy, 4);
  EXPECT_FALSE(w.render.auto_exposure);
  EXPECT_EQ(w.render.ev100, 12.5);
  EXPECT_EQ(w.render.exposure_compensation_ev, -1);
  EXPECT_EQ(w.render.tone_map, RenderSettings::ToneMap::kLinear);
  EXPECT_EQ(w.render.seed, 7u);

  // sky
  EXPECT_EQ(w.sky.type, Sky::Type::kDaylight);
  EXPECT_TRUE(w.sky.color.isApprox(Eigen::Vector3f(0.5f, 0.6f, 0.7f)));
  EXPECT_EQ(w.sky.luminance_cd_m2, 500);
  EXPECT_EQ(w.sky.turbidity, 2.5);
  EXPECT_EQ(w.sky.sun_elevation_deg, 30);
  EXPECT_EQ(w.sky.sun_azimuth_deg, -45);
  EXPECT_EQ(w.sky.zenith_luminance_cd_m2, 6000);

  // models: robots first (file order), then static models
  ASSERT_EQ(w.models.size(), 3u);
  EXPECT_EQ(w.models[0].name, "rover");
  EXPECT_TRUE(w.models[0].is_robot);
  EXPECT_EQ(w.models[0].file, Abs("models/rover.xml"));
  EXPECT_TRUE(fs::path(w.models[0].file).is_absolute());
  EXPECT_EQ(w.models[0].pose.xyz, Eigen::Vector3d(0, 0, 0.05));
  EXPECT_EQ(w.models[0].pose.rpy_deg, Eigen::Vector3d(0, 0, 90));
  EXPECT_EQ(w.models[0].controller.type, "waypoint_follower");
  EXPECT_EQ(w.models[0].controller.line, 25);
  EXPECT_EQ(w.models[1].name, "arm");
  EXPECT_TRUE(w.models[1].is_robot);
  EXPECT_EQ(w.models[1].file, Abs("models/arm.urdf"));
  EXPECT_TRUE(w.models[1].controller.type.empty());
  EXPECT_EQ(w.models[2].name, "room");
  EXPECT_FALSE(w.models[2].is_robot);
  EXPECT_EQ(w.models[2].pose.xyz, Eigen::Vector3d::Zero());

  // lights
  ASSERT_EQ(w.lights.size(), 4u);
  const LightConfig& sun = w.lights[0];
  EXPECT_EQ(sun.type, Light::Type::kDirectional);
  EXPECT_TRUE(sun.direction.isApprox(Eigen::Vector3d(0, 0, -1), 1e-15));  // normalised
  EXPECT_TRUE(sun.color.isApprox(Eigen::Vector3f(1, 0.9f, 0.8f)));
  EXPECT_EQ(sun.illuminance_lux, 20000);
  EXPECT_EQ(sun.angular_diameter_deg, 1);
  EXPECT_FALSE(sun.cast_shadow);
  EXPECT_EQ(sun.attach, "world");
  const LightConfig& lamp = w.lights[1];
  EXPECT_EQ(lamp.type, Light::Type::kPoint);
  EXPECT_EQ(lamp.attach, "rover/chassis");
  EXPECT_EQ(lamp.position, Eigen::Vector3d(0, 0, 3));
  EXPECT_EQ(lamp.power_w, 8);
  EXPECT_FALSE(lamp.intensity_cd.has_value());
  EXPECT_EQ(lamp.radius_m, 0.05);
  EXPECT_TRUE(lamp.cast_shadow);
  const LightConfig& torch = w.lights[2];
  EXPECT_EQ(torch.type, Light::Type::kSpot);
  EXPECT_TRUE(torch.direction.isApprox(Eigen::Vector3d(1, 0, 0), 1e-15));
  EXPECT_EQ(torch.intensity_cd, 500);
  EXPECT_EQ(torch.inner_angle_deg, 20);
  EXPECT_EQ(torch.outer_angle_deg, 35);
  const LightConfig& fill = w.lights[3];
  EXPECT_EQ(fill.type, Light::Type::kDirectional);
  EXPECT_EQ(fill.angular_diameter_deg, 0);  // directional = ideal distant source
  EXPECT_EQ(fill.illuminance_lux, 100);

  // cameras
  ASSERT_EQ(w.cameras.size(), 2u);
  const CameraConfig& front = w.cameras[0];
  EXPECT_EQ(front.name, "front");
  EXPECT_EQ(front.attach, "rover/chassis");
  EXPECT_EQ(front.pose.xyz, Eigen::Vector3d(0.2, 0, 0.1));
  EXPECT_EQ(front.pose.rpy_deg, Eigen::Vector3d(0, 10, 0));
  EXPECT_EQ(front.width, 320);
  EXPECT_EQ(front.height, 240);
  EXPECT_EQ(front.fovy_deg, 70);
  EXPECT_FALSE(front.intrinsics.has_value());
  EXPECT_EQ(front.rate_hz, 15);
  EXPECT_TRUE(front.outputs[ImageKind::kRgb] && front.outputs[ImageKind::kDepth] &&
              front.outputs[ImageKind::kSegmentation]);
  EXPECT_FALSE(front.is_mjcf_override);
  EXPECT_FALSE(front.auto_frame);
  const CameraConfig& cal = w.cameras[1];
  EXPECT_FALSE(cal.fovy_deg.has_value());
  ASSERT_TRUE(cal.intrinsics.has_value());
  EXPECT_EQ(cal.intrinsics->width, 1280);
  EXPECT_EQ(cal.intrinsics->height, 720);
  EXPECT_EQ(cal.intrinsics->fx, 900);
  EXPECT_EQ(cal.intrinsics->fy, 910);
  EXPECT_EQ(cal.intrinsics->cx, 640.5);
  EXPECT_EQ(cal.intrinsics->cy, 360.5);
  EXPECT_EQ(cal.rate_hz, 10);  // default
  EXPECT_FALSE(cal.outputs[ImageKind::kRgb]);
  EXPECT_TRUE(cal.outputs[ImageKind::kDepth]);
  EXPECT_FALSE(cal.outputs[ImageKind::kSegmentation]);

  // mjcf cameras: overrides inherit the block's defaults
  const MjcfCameraDefaults& mc = w.mjcf_cameras;
  EXPECT_FALSE(mc.enabled);
  EXPECT_EQ(mc.width, 800);
  EXPECT_EQ(mc.height, 600);
  EXPECT_EQ(mc.rate_hz, 5);
  EXPECT_TRUE(mc.outputs[ImageKind::kRgb] && !mc.outputs[ImageKind::kDepth] &&
              mc.outputs[ImageKind::kSegmentation]);
  ASSERT_EQ(mc.overrides.size(), 2u);
  EXPECT_EQ(mc.overrides[0].name, "rover/head");
  EXPECT_TRUE(mc.overrides[0].is_mjcf_override);
  EXPECT_EQ(mc.overrides[0].width, 320);
  EXPECT_EQ(mc.overrides[0].height, 240);
  EXPECT_EQ(mc.overrides[0].rate_hz, 30);
  EXPECT_EQ(mc.overrides[0].fovy_deg, 70);
  EXPECT_EQ(mc.overrides[0].near_m, 0.05);
  EXPECT_TRUE(mc.overrides[0].outputs[ImageKind::kRgb] &&
              mc.overrides[0].outputs[ImageKind::kDepth] &&
              !mc.overrides[0].outputs[ImageKind::kSegmentation]);
  EXPECT_EQ(mc.overrides[1].name, "room/corner");
  EXPECT_EQ(mc.overrides[1].width, 800);
  EXPECT_EQ(mc.overrides[1].height, 600);
  EXPECT_EQ(mc.overrides[1].rate_hz, 5);
  EXPECT_FALSE(mc.overrides[1].fovy_deg.has_value());
  ASSERT_TRUE(mc.overrides[1].intrinsics.has_value());
  EXPECT_EQ(mc.overrides[1].intrinsics->cx, 399.5);  // image centre (800 - 1) / 2
  EXPECT_EQ(mc.overrides[1].intrinsics->cy, 299.5);

  // materials, in file order
  ASSERT_EQ(w.materials.size(), 2u);
  EXPECT_EQ(w.materials[0].name, "room/floor");
  EXPECT_TRUE(w.materials[0].base_color->isApprox(Eigen::Vector3f(0.5f, 0.4f, 0.3f)));
  EXPECT_EQ(w.materials[0].roughness, 0.6f);
  EXPECT_EQ(w.materials[0].metallic, 0.0f);
  EXPECT_EQ(w.materials[0].specular, 0.25f);
  EXPECT_TRUE(w.materials[0].emission->isApprox(Eigen::Vector3f(1, 2, 3)));
  EXPECT_EQ(w.materials[1].name, "rover/paint");
  EXPECT_EQ(w.materials[1].metallic, 1.0f);
  EXPECT_FALSE(w.materials[1].base_color.has_value());
  EXPECT_FALSE(w.materials[1].roughness.has_value());

  EXPECT_NO_THROW(w.ValidateOrThrow());
}

TEST_F(WorldConfigTest, ControllerParamsKeptAsYaml) {
  const WorldConfig w = ParseWorld(kFullWorld, world_);
  const ConfigValue& p = w.models[0].controller.params;
  EXPECT_EQ(w.models[0].controller.line, 25);
  ASSERT_TRUE(p.IsMap());
  EXPECT_EQ(p.size(), 2u);  // type is not repeated
  EXPECT_FALSE(p["type"]);
  double v = 0;
  EXPECT_TRUE(p["speed_m_s"].ToDouble(&v));
  EXPECT_EQ(v, 0.5);
  ASSERT_TRUE(p["waypoints"].IsSequence());
  ASSERT_EQ(p["waypoints"].size(), 2u);
  EXPECT_TRUE(p["waypoints"][1][1].ToDouble(&v));
  EXPECT_EQ(v, 1.0);
  // the world file's own nodes, not a re-parsed copy: they keep their place in the file
  EXPECT_EQ(p["speed_m_s"].line(), 27);
  EXPECT_EQ(p["waypoints"].line(), 28);
}

TEST_F(WorldConfigTest, ControllerWithOnlyTypeHasEmptyMapParams) {
  const WorldConfig w = ParseWorld(
      "robots:\n  - name: r\n    file: models/rover.xml\n    controller: {type: idle}\n", world_);
  EXPECT_EQ(w.models[0].controller.type, "idle");
  EXPECT_EQ(w.models[0].controller.line, 4);
  const ConfigValue& p = w.models[0].controller.params;
  EXPECT_TRUE(p.IsMap());
  EXPECT_EQ(p.size(), 0u);
}

TEST_F(WorldConfigTest, EmptyMappingGivesDefaults) {
  const WorldConfig w = ParseWorld("{}\n", world_);
  const WorldConfig d;
  EXPECT_EQ(w.seed, d.seed);
  EXPECT_EQ(w.duration_sec, d.duration_sec);
  EXPECT_FALSE(w.timestep_sec.has_value());
  EXPECT_TRUE(w.models.empty());
  EXPECT_TRUE(w.lights.empty());
  EXPECT_TRUE(w.cameras.empty());
  EXPECT_EQ(w.sky.type, Sky::Type::kUniform);
  EXPECT_EQ(w.render.tier, RenderSettings::Tier::kRealtime);
  EXPECT_EQ(w.render.backend, RenderSettings::Backend::kAuto);
  EXPECT_EQ(w.render.samples_per_pixel, 16);
  EXPECT_TRUE(w.render.auto_exposure);
  EXPECT_TRUE(w.mjcf_cameras.enabled);
  EXPECT_EQ(w.output_dir, "out");
}

TEST_F(WorldConfigTest, RenderBackendIsRead) {
  EXPECT_EQ(ParseWorld("render:\n  backend: embree\n", world_).render.backend,
            RenderSettings::Backend::kEmbree);
  EXPECT_EQ(ParseWorld("render:\n  backend: cpu\n", world_).render.backend,
            RenderSettings::Backend::kEmbree);
  EXPECT_EQ(ParseWorld("render:\n  backend: cuda\n", world_).render.backend,
            RenderSettings::Backend::kCuda);
  EXPECT_EQ(ParseWorld("render:\n  backend: auto\n", world_).render.backend,
            RenderSettings::Backend::kAuto);
}

TEST_F(WorldConfigTest, KeysWithoutValueMeanEmptyListOrMapping) {
  const WorldConfig w = ParseWorld("lights:\nmaterials:\nrender:\nrobots:\nseed: 4\n", world_);
  EXPECT_TRUE(w.lights.empty());
  EXPECT_TRUE(w.materials.empty());
  EXPECT_TRUE(w.models.empty());
  EXPECT_EQ(w.render.samples_per_pixel, 16);
  EXPECT_EQ(w.render.seed, 4u);
}

TEST_F(WorldConfigTest, ScalarKeyWithoutValueIsAnError) {
  // the line is the key's, although yaml-cpp marks the empty value on the next line
  ExpectError("seed:\nduration_sec: 3\n", 1, "seed", "expected a non-negative integer");
}

TEST_F(WorldConfigTest, CameraDefaultsToFovy60AndRgb) {
  const WorldConfig w = ParseWorld("cameras:\n  - name: c\n", world_);
  ASSERT_EQ(w.cameras.size(), 1u);
  EXPECT_EQ(w.cameras[0].fovy_deg, 60);
  EXPECT_EQ(w.cameras[0].width, 640);
  EXPECT_EQ(w.cameras[0].height, 480);
  EXPECT_TRUE(w.cameras[0].outputs[ImageKind::kRgb]);
  EXPECT_FALSE(w.cameras[0].outputs[ImageKind::kDepth]);
  EXPECT_EQ(w.cameras[0].attach, "world");
  EXPECT_EQ(w.cameras[0].near_m, 0.01);
}

TEST_F(WorldConfigTest, CameraNearClip) {
  const WorldConfig w = ParseWorld("cameras:\n  - {name: c, near_m: 0.2}\n", world_);
  EXPECT_EQ(w.cameras[0].near_m, 0.2);
  ExpectError("cameras:\n  - name: c\n    near_m: -0.01\n", 3, "cameras[0].near_m",
              "got -0.01; expected [0, 10]");
}

TEST_F(WorldConfigTest, PathsResolveAgainstWorldFolder) {
  fs::create_directories(dir_ / "worlds");
  const std::string nested = (dir_ / "worlds" / "w.yaml").string();
  const std::string abs_room = Abs("models/room.xml");
  const WorldConfig w = ParseWorld(
      "models:\n  - {name: a, file: ../models/rover.xml}\n"
      "  - {name: b, file: " +
          abs_room + "}\n",
      nested);
  EXPECT_EQ(w.models[0].file, Abs("models/rover.xml"));  // ".." normalised away
  EXPECT_EQ(w.models[1].file, abs_room);
}

TEST_F(WorldConfigTest, LoadWorldFileReadsFromDisk) {
  WriteFile(world_, kFullWorld);
  const WorldConfig a = LoadWorldFile(world_);
  const WorldConfig b = ParseWorld(kFullWorld, world_);
  EXPECT_EQ(a.file, world_);
  ASSERT_EQ(a.models.size(), b.models.size());
  for (size_t i = 0; i < a.models.size(); ++i) EXPECT_EQ(a.models[i].file, b.models[i].file);
  EXPECT_EQ(EmitYamlFlow(a.models[0].controller.params),
            EmitYamlFlow(b.models[0].controller.params));
  EXPECT_EQ(a.lights.size(), 4u);
}

TEST_F(WorldConfigTest, LoadWorldFileMissingFileNamesPath) {
  const std::string missing = (dir_ / "nope.yaml").string();
  try {
    LoadWorldFile(missing);
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.file(), missing);
    EXPECT_NE(std::string(e.what()).find("not found: " + missing), std::string::npos) << e.what();
  }
}

TEST_F(WorldConfigTest, ErrorMessageFromDiskNamesFileAndLine) {
  WriteFile(world_, "seed: 1\nduration_sec: -3\n");
  try {
    LoadWorldFile(world_);
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), world_ + ":2: duration_sec: got -3; expected (0, 1e+06]");
  }
}

// ---- malformed input: one test per error class ----

TEST_F(WorldConfigTest, YamlSyntaxErrorHasYamlCppLine) {
  ExpectError("seed: 1\nsky:\n  type: uniform\n   color: [1, 1, 1]\n", 4, "", "YAML syntax error");
}

TEST_F(WorldConfigTest, UnclosedFlowListIsSyntaxError) {
  ExpectError("seed: 1\nlights: [\n  {name: a, type: point, power_w: 1}\nseed: 2\n", 4, "",
              "YAML syntax error");
}

TEST_F(WorldConfigTest, UnknownTopLevelKeyListsAllowedKeys) {
  ExpectError("seed: 1\nduration: 5\n", 2, "duration",
              "unknown key 'duration'; expected one of: seed, duration_sec, physics");
}

TEST_F(WorldConfigTest, UnknownNestedKeyListsAllowedKeys) {
  ExpectError("lights:\n  - name: a\n    type: point\n    colour: [1, 1, 1]\n    intensity_cd: 5\n",
              4, "lights[0].colour", "expected one of: name, type, attach, color, cast_shadow");
}

TEST_F(WorldConfigTest, KeyOfAnotherLightTypeIsRejected) {
  ExpectError(
      "lights:\n  - name: s\n    type: sun\n    illuminance_lux: 1000\n"
      "    intensity_cd: 5\n",
      5, "lights[0].intensity_cd", "does not apply to a sun light");
}

TEST_F(WorldConfigTest, NotANumber) {
  ExpectError("seed: 1\nduration_sec: ten\n", 2, "duration_sec", "expected a number, got 'ten'");
}

TEST_F(WorldConfigTest, QuotedNumberIsAString) {
  ExpectError("duration_sec: \"5\"\n", 1, "duration_sec",
              "expected a number, got the quoted string \"5\"");
}

TEST_F(WorldConfigTest, NegativeSeed) {
  ExpectError("seed: -1\n", 1, "seed", "expected a non-negative integer");
}

TEST_F(WorldConfigTest, NotAnInteger) {
  ExpectError("cameras:\n  - name: c\n    width: 640.5\n", 3, "cameras[0].width",
              "expected an integer, got '640.5'");
}

TEST_F(WorldConfigTest, VectorOfWrongLength) {
  ExpectError(
      "robots:\n  - name: rover\n    file: models/rover.xml\n    pose:\n      xyz: [0, 0]\n", 5,
      "robots[0].pose.xyz", "expected a list of 3 numbers, got a list of 2");
}

TEST_F(WorldConfigTest, VectorElementNotANumberNamesElement) {
  ExpectError("sky:\n  color: [0.1,\n    x, 0.3]\n", 3, "sky.color[1]", "expected a number");
}

TEST_F(WorldConfigTest, ListExpected) {
  ExpectError("robots:\n  name: rover\n", 1, "robots", "expected a list");
}

TEST_F(WorldConfigTest, MappingExpected) {
  ExpectError("render: pathtraced\n", 1, "render", "expected a mapping");
}

TEST_F(WorldConfigTest, BooleanExpected) {
  ExpectError("render:\n  denoise: maybe\n", 2, "render.denoise", "expected true or false");
}

TEST_F(WorldConfigTest, RateOutOfRange) {
  ExpectError("cameras:\n  - name: c\n    rate_hz: 0\n", 3, "cameras[0].rate_hz",
              "got 0; expected (0, 10000]");
}

TEST_F(WorldConfigTest, TimestepOutOfRange) {
  ExpectError("physics:\n  timestep_sec: 0.5\n", 2, "physics.timestep_sec",
              "got 0.5; expected [1e-06, 0.1]");
}

// the physics block reads each key once (ParamReader::Find) and reports the others with the keys
// it read (ReportUnused): the same message as the up-front list it replaced
TEST_F(WorldConfigTest, PhysicsUnknownKeyListsTheKeysRead) {
  ExpectError("physics:\n  timestep_sec: 0.002\n  integrater: RK4\n", 3, "physics.integrater",
              "unknown key 'integrater'; expected one of: timestep_sec, integrator, gravity_mps2, "
              "solver_iterations, cone");
}

TEST_F(WorldConfigTest, RenderSamplesOutOfRangeNamesWorldFileAndLine) {
  ExpectError("seed: 3\nrender:\n  tier: pathtraced\n  samples_per_pixel: 0\n", 4,
              "render.samples_per_pixel", "got 0; expected [1, 65536]");
}

TEST_F(WorldConfigTest, MaxAnisotropyOutOfRange) {
  ExpectError("render:\n  max_anisotropy: 0\n", 2, "render.max_anisotropy",
              "got 0; expected [1, 64]");
}

TEST_F(WorldConfigTest, ManualEv100OutOfRange) {
  ExpectError("render:\n  exposure:\n    mode: manual\n    ev100: 31\n", 4, "render.exposure.ev100",
              "got 31; expected [-10, 30]");
}

TEST_F(WorldConfigTest, TurbidityOutOfRange) {
  ExpectError("sky: {type: daylight, turbidity: 12}\n", 1, "sky.turbidity",
              "got 12; expected [1.7, 10]");
}

TEST_F(WorldConfigTest, ColorComponentOutOfRange) {
  ExpectError(
      "lights:\n  - name: a\n    type: point\n    intensity_cd: 5\n"
      "    color: [1, 1.5, 1]\n",
      5, "lights[0].color", "component 1 is 1.5; expected each of the 3 numbers in [0, 1]");
}

TEST_F(WorldConfigTest, ImageSizeOutOfRange) {
  ExpectError(
      "mjcf_cameras:\n  overrides:\n    rover/head: {height: 20000}\n"
      "robots: [{name: rover, file: models/rover.xml}]\n",
      3, "mjcf_cameras.overrides.rover/head.height", "expected [1, 16384]");
}

TEST_F(WorldConfigTest, MissingRequiredModelFile) {
  ExpectError("seed: 1\nrobots:\n  - name: rover\n    pose: {xyz: [0, 0, 1]}\n", 3,
              "robots[0].file", "required key 'file' is missing");
}

TEST_F(WorldConfigTest, MissingRequiredLightName) {
  ExpectError("lights:\n  - type: point\n    power_w: 3\n", 2, "lights[0].name",
              "required key 'name' is missing");
}

TEST_F(WorldConfigTest, MissingSunIlluminance) {
  ExpectError(
      "lights:\n  - name: a\n    type: point\n    power_w: 1\n"
      "  - name: sun\n    type: sun\n",
      5, "lights[1].illuminance_lux", "required for sun and directional lights");
}

TEST_F(WorldConfigTest, MissingControllerType) {
  ExpectError(
      "robots:\n  - name: r\n    file: models/rover.xml\n    controller:\n"
      "      speed_m_s: 1\n",
      4, "robots[0].controller.type", "required key 'type' is missing");
}

TEST_F(WorldConfigTest, PointLightNeedsExactlyOneOfIntensityOrPower) {
  ExpectError("lights:\n  - name: a\n    type: point\n    intensity_cd: 5\n    power_w: 2\n", 5,
              "lights[0].power_w", "expected exactly one of them");
  ExpectError("lights:\n  - name: a\n    type: spot\n", 2, "lights[0]",
              "neither intensity_cd nor power_w given");
}

TEST_F(WorldConfigTest, SpotInnerAngleLargerThanOuter) {
  ExpectError(
      "lights:\n  - name: a\n    type: spot\n    power_w: 2\n    inner_angle_deg: 50\n"
      "    outer_angle_deg: 40\n",
      5, "lights[0].inner_angle_deg", "expected 0 < inner <= outer <= 90");
}

TEST_F(WorldConfigTest, ZeroDirection) {
  ExpectError(
      "lights:\n  - name: s\n    type: sun\n    illuminance_lux: 5\n"
      "    direction: [0, 0, 0]\n",
      5, "lights[0].direction", "expected a non-zero direction");
}

TEST_F(WorldConfigTest, DuplicateModelNameAcrossRobotsAndModels) {
  ExpectError(
      "robots:\n  - name: rover\n    file: models/rover.xml\nmodels:\n"
      "  - name: rover\n    file: models/room.xml\n",
      5, "models[0].name", "duplicate name 'rover' (also robots[0].name, line 2)");
}

TEST_F(WorldConfigTest, DuplicateCameraName) {
  ExpectError("cameras:\n  - name: c\n  - name: d\n  - name: c\n", 4, "cameras[2].name",
              "duplicate name 'c' (also cameras[0].name, line 2)");
}

TEST_F(WorldConfigTest, DuplicateYamlKey) {
  ExpectError("seed: 1\nduration_sec: 3\nseed: 2\n", 3, "seed",
              "key 'seed' appears twice (first on line 1)");
}

TEST_F(WorldConfigTest, InvalidModelName) {
  ExpectError("models:\n  - name: my/room\n    file: models/room.xml\n", 2, "models[0].name",
              "characters other than letters, digits, '_' or '-'");
}

TEST_F(WorldConfigTest, MissingModelFileNamesResolvedPath) {
  ExpectError("robots:\n  - name: r\n    file: models/missing.xml\n", 3, "robots[0].file",
              "file not found: " + Abs("models/missing.xml"));
}

TEST_F(WorldConfigTest, WrongModelExtension) {
  ExpectError("models:\n  - name: r\n    file: models/room.step\n", 3, "models[0].file",
              "expected an MJCF (.xml) or URDF (.urdf) file");
}

TEST_F(WorldConfigTest, ControllerNotAllowedOnStaticModel) {
  ExpectError("models:\n  - name: r\n    file: models/room.xml\n    controller: {type: x}\n", 4,
              "models[0].controller",
              "unknown key 'controller'; expected one of: name, file, pose");
}

TEST_F(WorldConfigTest, UnknownEnumValueListsValidOnes) {
  ExpectError("render:\n  tier: fast\n", 2, "render.tier",
              "unknown value 'fast'; expected one of: realtime, pathtraced");
  ExpectError("render:\n  backend: optix\n", 2, "render.backend",
              "unknown value 'optix'; expected one of: cpu, embree, cuda, auto");
  ExpectError("lights:\n  - name: a\n    type: area\n", 3, "lights[0].type",
              "expected one of: sun, directional, point, spot");
}

TEST_F(WorldConfigTest, UnknownCameraOutput) {
  ExpectError("cameras:\n  - name: c\n    outputs:\n      - rgb\n      - thermal\n", 5,
              "cameras[0].outputs[1]", "expected one of: rgb, depth, segmentation");
}

TEST_F(WorldConfigTest, EmptyCameraOutputs) {
  ExpectError("cameras:\n  - name: c\n    outputs: []\n", 3, "cameras[0].outputs",
              "expected a non-empty list of: rgb, depth, segmentation");
}

TEST_F(WorldConfigTest, FovyTogetherWithIntrinsics) {
  ExpectError("cameras:\n  - name: c\n    fovy_deg: 60\n    intrinsics: {fx: 500, fy: 500}\n", 4,
              "cameras[0].intrinsics", "fovy_deg and intrinsics both given; expected one of them");
}

TEST_F(WorldConfigTest, IntrinsicsFocalLengthMustBePositive) {
  ExpectError("cameras:\n  - name: c\n    intrinsics:\n      fx: 500\n      fy: -1\n", 5,
              "cameras[0].intrinsics.fy", "got -1; expected > 0");
}

TEST_F(WorldConfigTest, AttachToUnknownModel) {
  ExpectError(
      "robots: [{name: rover, file: models/rover.xml}]\n"
      "cameras:\n  - name: c\n    attach: rovr/chassis\n",
      4, "cameras[0].attach", "unknown model 'rovr'; expected one of: rover");
  ExpectError("cameras:\n  - name: c\n    attach: chassis\n", 3, "cameras[0].attach",
              "expected \"world\" or a body as \"<model>/<body>\"");
}

TEST_F(WorldConfigTest, MaterialOverrideNeedsKnownModelPrefix) {
  ExpectError(
      "models: [{name: room, file: models/room.xml}]\n"
      "materials:\n  floor: {roughness: 0.5}\n",
      3, "materials.floor", "expected \"<model>/<material>\"");
}

TEST_F(WorldConfigTest, MaterialValueOutOfRange) {
  ExpectError(
      "models: [{name: room, file: models/room.xml}]\n"
      "materials:\n  room/floor:\n    roughness: 1.5\n",
      4, "materials.room/floor.roughness", "got 1.5; expected [0, 1]");
}

TEST_F(WorldConfigTest, EmptyDocument) {
  ExpectError("", 1, "", "the world file is empty; expected a mapping");
}

TEST_F(WorldConfigTest, NonFiniteNumberRejected) {
  ExpectError("duration_sec: .inf\n", 1, "duration_sec", "expected a number");
  ExpectError("duration_sec: nan\n", 1, "duration_sec", "expected a finite number");
}

// the complete example of the reference must load as documented.
TEST_F(WorldConfigTest, ReferenceExampleParses) {
  std::ifstream in(std::string(PENUMBRA_SOURCE_DIR) + "/docs/world-file.md");
  ASSERT_TRUE(in) << "docs/world-file.md not found";
  std::stringstream text;
  text << in.rdbuf();
  const std::string doc = text.str();
  const size_t heading = doc.find("### Complete example");
  ASSERT_NE(heading, std::string::npos);
  const size_t begin = doc.find("```yaml\n", heading);
  ASSERT_NE(begin, std::string::npos);
  const size_t end = doc.find("```", begin + 8);
  ASSERT_NE(end, std::string::npos);
  const WorldConfig w = ParseWorld(doc.substr(begin + 8, end - begin - 8), world_);
  EXPECT_EQ(w.seed, 7u);
  EXPECT_EQ(w.models.size(), 2u);
  EXPECT_EQ(w.lights.size(), 3u);
  EXPECT_EQ(w.cameras.size(), 2u);
  EXPECT_EQ(w.mjcf_cameras.overrides.size(), 1u);
  EXPECT_EQ(w.materials.size(), 1u);
  EXPECT_EQ(w.models[0].controller.type, "waypoint_follower");
}

// ---- programmatic configs ----

TEST_F(WorldConfigTest, ValidateOrThrowWithoutLinesUsesLineZero) {
  WorldConfig w = ParseWorld("models: [{name: room, file: models/room.xml}]\n", world_);
  w.models[0].controller.type = "waypoint_follower";  // static models take no controller
  try {
    w.ValidateOrThrow();
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.file(), world_);
    EXPECT_EQ(e.line(), 0);
    EXPECT_EQ(e.key(), "models[0].controller");
  }
  w.models[0].controller.type.clear();
  w.cameras.push_back(CameraConfig{});
  w.cameras[0].name = "c";
  w.cameras[0].fovy_deg = 60;
  w.cameras[0].intrinsics = CameraIntrinsics::FromFovy(640, 480, 60);
  EXPECT_THROW(w.ValidateOrThrow(), ConfigError);
  w.cameras[0].fovy_deg.reset();
  EXPECT_NO_THROW(w.ValidateOrThrow());
  w.cameras[0].intrinsics->width = 320;  // must match the camera's image size
  EXPECT_THROW(w.ValidateOrThrow(), ConfigError);
}

// ---- bare model ----

TEST_F(WorldConfigTest, WorldForBareModel) {
  const fs::path model = dir_ / "models" / "my humanoid.v2.xml";
  WriteFile(model, kMinimalMjcf);
  const WorldConfig w = WorldForBareModel(model.string());
  EXPECT_EQ(w.file, "");
  ASSERT_EQ(w.models.size(), 1u);
  EXPECT_EQ(w.models[0].name, "my_humanoid_v2");
  EXPECT_FALSE(w.models[0].is_robot);
  EXPECT_EQ(w.models[0].file, model.lexically_normal().string());
  EXPECT_TRUE(w.models[0].pose.ToPose().isApprox(Pose::Identity()));
  EXPECT_TRUE(w.default_lights);
  EXPECT_TRUE(w.lights.empty());
  EXPECT_EQ(w.sky.type, Sky::Type::kDaylight);
  EXPECT_EQ(w.duration_sec, 10);
  EXPECT_TRUE(w.mjcf_cameras.enabled);
  ASSERT_EQ(w.cameras.size(), 1u);
  const CameraConfig& c = w.cameras[0];
  EXPECT_EQ(c.name, "default");
  EXPECT_TRUE(c.auto_frame);
  EXPECT_EQ(c.attach, "world");
  EXPECT_EQ(c.width, 640);
  EXPECT_EQ(c.height, 480);
  EXPECT_EQ(c.fovy_deg, 45);
  EXPECT_EQ(c.rate_hz, 30);
  EXPECT_TRUE(c.outputs[ImageKind::kRgb] && c.outputs[ImageKind::kDepth] &&
              c.outputs[ImageKind::kSegmentation]);

  EXPECT_FALSE(w.ground_plane);  // an MJCF brings its own floor (or floats on purpose)

  const WorldConfig u = WorldForBareModel((dir_ / "models" / "arm.urdf").string());
  EXPECT_EQ(u.models[0].name, "arm");
  EXPECT_TRUE(u.ground_plane);  // a URDF has none
}

TEST_F(WorldConfigTest, WorldForBareModelErrors) {
  const std::string missing = (dir_ / "models" / "ghost.xml").string();
  try {
    WorldForBareModel(missing);
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.file(), missing);
    EXPECT_NE(std::string(e.what()).find("file not found: " + missing), std::string::npos)
        << e.what();
  }
  WriteFile(dir_ / "models" / "mesh.obj", "v 0 0 0\n");
  EXPECT_THROW(WorldForBareModel((dir_ / "models" / "mesh.obj").string()), ConfigError);
}

}  // namespace
}  // namespace penumbra

namespace penumbra {
namespace {

// ---- nothing in a world file is silently ignored, every error is placed ----

TEST_F(WorldConfigTest, SecondYamlDocumentIsAnError) {
  ExpectError("seed: 1\n---\nduration_sec: 5\n", 3, "", "a second YAML document");
  // a trailing '---' with nothing after it is harmless
  EXPECT_EQ(ParseWorld("seed: 3\n---\n", world_).seed, 3u);
}

TEST_F(WorldConfigTest, HugeValueIsEchoedShortened) {
  const std::string name(10 * 1024 * 1024, 'n');
  try {
    ParseWorld("lights:\n  - name: " + name + "!\n    type: point\n    power_w: 1\n", world_);
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.line(), 2);
    EXPECT_LT(std::string(e.what()).size(), 2000u);
    // the name check quotes 16 characters; other values are cut with "bytes elided"
    EXPECT_NE(std::string(e.what()).find("a name of 10485761 characters ('nnnnnnnnnnnnnnnn...')"),
              std::string::npos)
        << e.what();
  }
}

TEST_F(WorldConfigTest, BinaryGarbageIsEscaped) {
  try {
    ParseWorld(std::string("seed: 1\n\x01\x02\xff\xfe: 3\n"), world_);
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    const std::string what = e.what();
    for (char c : what) EXPECT_TRUE(c >= 0x20 && c < 0x7f) << what;
  }
}

TEST_F(WorldConfigTest, LocateInWorldPlacesStageErrors) {
  const std::string yaml =
      "seed: 1\n"
      "models:\n"
      "  - {name: room, file: models/room.xml}\n"
      "effects:\n"
      "  - name: flicker\n"
      "    type: light_event\n"
      "    light: lamp\n"
      "materials:\n"
      "  room/floor: {roughness: 0.5}\n";
  WorldConfig w = ParseWorld(yaml, world_);
  w.file = world_;
  // an error raised by a stage with no file, and one with the file but no line
  const ConfigError a = LocateInWorld(w, ConfigError("", 0, "effects[0].light", "no such light"));
  EXPECT_EQ(a.file(), world_);
  EXPECT_EQ(a.line(), 7);
  EXPECT_EQ(std::string(a.what()), world_ + ":7: effects[0].light: no such light");
  const ConfigError b = LocateInWorld(w, ConfigError(world_, 0, "materials.room/floor", "x"));
  EXPECT_EQ(b.line(), 9);
  // command-line flags and errors in other files keep their origin
  EXPECT_EQ(LocateInWorld(w, ConfigError("", 0, "--out", "x")).file(), "");
  EXPECT_EQ(LocateInWorld(w, ConfigError("m.xml", 0, "geom", "x")).file(), "m.xml");
  // a bare-model world (no file) changes nothing
  WorldConfig bare;
  EXPECT_EQ(LocateInWorld(bare, ConfigError("", 0, "effects[0].light", "x")).file(), "");
}

TEST_F(WorldConfigTest, MissingVdbFileIsFoundAtLoad) {
  ExpectError("effects:\n  - name: v\n    type: vdb_smoke\n    file: nothere.vdb\n", 4,
              "effects[0].file", "file not found");
}

}  // namespace
}  // namespace penumbra
