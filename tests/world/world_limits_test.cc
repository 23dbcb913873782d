// finite but absurd world-file values (poses of 1e19 m, intrinsics
// of 1e300 px, timesteps of 1e-300 s, durations of 1e308 s, LiDARs of 1e9 columns, plume
// steps of 1e-9 s) are refused at load with the file, line, key and the accepted range
// (scene/scene_limits.h, docs/world-file.md "Input limits").

#include <gtest/gtest.h>

#include <string>

#include "common/temp_dir.h"
#include "penumbra/core/error.h"
#include "penumbra/scene/scene_limits.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

class WorldLimitsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_.Write(
        "m.xml",
        R"(<mujoco><worldbody><body name="b"><geom type="box" size="0.1 0.1 0.1"/></body></worldbody></mujoco>)");
    world_ = (dir_.path() / "world.yaml").string();
  }

  // parses `yaml` and expects a ConfigError at `line` for `key` whose message contains `text`.
  void ExpectError(const std::string& yaml, int line, const std::string& key,
                   const std::string& text) {
    try {
      ParseWorld(yaml, world_);
      ADD_FAILURE() << "no ConfigError for:\n" << yaml;
    } catch (const ConfigError& e) {
      const std::string what = e.what();
      EXPECT_EQ(e.file(), world_) << what;
      EXPECT_EQ(e.line(), line) << what;
      EXPECT_EQ(e.key(), key) << what;
      EXPECT_NE(what.find(text), std::string::npos) << "expected '" << text << "' in: " << what;
    }
  }

  penumbra::testing::TempDir dir_;
  std::string world_;
};

TEST_F(WorldLimitsTest, RobotAndModelPositionsAreBounded) {
  ExpectError("robots:\n  - {name: r, file: m.xml, pose: {xyz: [1e19, 0, 0]}}\n", 2,
              "robots[0].pose.xyz",
              "component 0 is 1e+19; expected each of the 3 numbers in [-1e+05, 1e+05]");
  // 1e17 used to exit 1 with "physics diverged at t = 0"
  ExpectError("models:\n  - {name: m, file: m.xml, pose: {xyz: [0, -1e17, 0]}}\n", 2,
              "models[0].pose.xyz", "component 1 is -1e+17");
  // the limit itself is accepted
  EXPECT_NO_THROW(
      ParseWorld("models:\n  - {name: m, file: m.xml, pose: {xyz: [1e5, -1e5, 0]}}\n", world_));
}

TEST_F(WorldLimitsTest, CameraAndLightPositionsAreBounded) {
  ExpectError("cameras:\n  - name: c\n    pose: {xyz: [0, 0, 1e300]}\n", 3, "cameras[0].pose.xyz",
              "component 2 is 1e+300");
  ExpectError("lights:\n  - {name: l, type: point, position: [2e5, 0, 3], intensity_cd: 10}\n", 2,
              "lights[0].position", "component 0 is 2e+05");
}

TEST_F(WorldLimitsTest, IntrinsicsAreCheckedAgainstTheImageSize) {
  // cx 1e300: rays of every pixel almost parallel to the image plane
  ExpectError(
      "cameras:\n  - name: c\n    width: 32\n    height: 24\n"
      "    intrinsics: {fx: 30, fy: 30, cx: 1e300, cy: 12}\n",
      5, "cameras[0].intrinsics", "horizontal field of view reaches 180 deg");
  // fx = fy = 1e-300: a field of view of 180 deg
  ExpectError(
      "cameras:\n  - name: c\n    width: 32\n    height: 24\n"
      "    intrinsics: {fx: 1e-300, fy: 1e-300}\n",
      5, "cameras[0].intrinsics", "expected every pixel within 89.5 deg of the optical axis");
  // a principal point off the image is fine while the rays stay within 89.5 deg
  EXPECT_NO_THROW(
      ParseWorld("cameras:\n  - name: c\n    width: 32\n    height: 24\n"
                 "    intrinsics: {fx: 30, fy: 30, cx: -40, cy: 60}\n",
                 world_));
  // the same rule for MJCF camera overrides
  ExpectError(
      "models:\n  - {name: m, file: m.xml}\nmjcf_cameras:\n  overrides:\n    m/cam:\n"
      "      intrinsics: {fx: 1e-3, fy: 100}\n",
      6, "mjcf_cameras.overrides.m/cam.intrinsics", "horizontal field of view");
}

TEST_F(WorldLimitsTest, DurationsAndTimestepsAreBounded) {
  ExpectError("duration_sec: 1e308\n", 1, "duration_sec", "expected (0, 1e+06]");
  EXPECT_NO_THROW(ParseWorld("duration_sec: 1e6\n", world_));
  ExpectError("physics:\n  timestep_sec: 1e-300\n", 2, "physics.timestep_sec",
              "expected [1e-06, 0.1]");
  ExpectError("physics:\n  timestep_sec: 0\n", 2, "physics.timestep_sec", "expected [1e-06, 0.1]");
  EXPECT_NO_THROW(ParseWorld("physics:\n  timestep_sec: 1e-6\n", world_));
}

TEST_F(WorldLimitsTest, LidarColumnsAndSensorPosesAreBounded) {
  ExpectError(
      "sensors:\n  - name: l\n    type: lidar\n    preset: velodyne_vlp16\n"
      "    columns: 1000000000\n",
      5, "sensors[0].columns", "expected an integer in [1, 4194304]");
  ExpectError(
      "sensors:\n  - name: l\n    type: lidar\n    preset: velodyne_vlp16\n"
      "    pose: {xyz: [0, 1e19, 0]}\n",
      5, "sensors[0].pose.xyz", "expected each of the 3 numbers in [-1e+05, 1e+05]");
}

TEST_F(WorldLimitsTest, PlumeStepCannotBeTiny) {
  // 1e-9 s was inside the documented (0, 0.1] and took 1e9 fluid steps per simulated second
  const std::string plume =
      "effects:\n  - name: s\n    type: smoke\n    mode: plume\n"
      "    region: {min: [0, 0, 0], max: [1, 1, 1]}\n"
      "    emitters: [{position: [0.5, 0.5, 0.1]}]\n"
      "    dt_sec: ";
  try {
    ParseWorld(plume + "1e-9\n", world_);
    ADD_FAILURE() << "no ConfigError for dt_sec 1e-9";
  } catch (const ConfigError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("effects[0].dt_sec"), std::string::npos) << what;
    EXPECT_NE(what.find("[0.001, 0.1]"), std::string::npos) << what;
  }
  EXPECT_NO_THROW(ParseWorld(plume + "0.001\n", world_));
}

}  // namespace
}  // namespace penumbra
