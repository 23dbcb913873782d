// nonsense that world files must not get through silently. YAML tags
// (`!foo 3`, `!!binary`) are refused instead of dropped; fields of view narrower than 0.1 deg
// (fovy_deg 1e-300 gave fx = 2.75e303) and intrinsics far off the image are refused; names
// longer than 64 characters are refused with the file and line (a 100 KB camera name used to
// exit 1 with no line and print 100 KB); every error quotes at most a bounded part of the
// input. docs/world-file.md ("Input limits").

#include <gtest/gtest.h>

#include <string>

#include "common/temp_dir.h"
#include "penumbra/core/error.h"
#include "penumbra/core/text_match.h"
#include "penumbra/world/adversity_preset.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

class WorldNonsenseTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_.Write(
        "m.xml",
        R"(<mujoco><worldbody><body name="b"><geom type="box" size="0.1 0.1 0.1"/></body></worldbody></mujoco>)");
    world_ = (dir_.path() / "world.yaml").string();
  }

  // parses `yaml` and expects a ConfigError at `line` for `key` whose message contains `text`;
  // returns the message.
  std::string ExpectRefused(const std::string& yaml, int line, const std::string& key,
                            const std::string& text) {
    try {
      ParseWorld(yaml, world_);
      ADD_FAILURE() << "no ConfigError for:\n" << yaml.substr(0, 300);
    } catch (const ConfigError& e) {
      const std::string what = e.what();
      EXPECT_EQ(e.file(), world_) << what;
      EXPECT_EQ(e.line(), line) << what;
      EXPECT_EQ(e.key(), key) << what;
      EXPECT_NE(what.find(text), std::string::npos) << "expected '" << text << "' in: " << what;
      return what;
    }
    return "";
  }

  penumbra::testing::TempDir dir_;
  std::string world_;
};

TEST_F(WorldNonsenseTest, YamlTagsAreRefusedWithTheirLine) {
  // a local tag on a number used to be dropped: the value was read as 3
  ExpectRefused("duration_sec: 1\nseed: !foo 3\n", 2, "", "YAML tag '!foo' is not supported");
  // a standard tag (shown in its short form) on a mapping and on a binary blob
  ExpectRefused("render: !!map {tier: realtime}\n", 1, "", "YAML tag '!!map'");
  ExpectRefused("duration_sec: 1\noutput:\n  dir: !!binary aGVsbG8=\n", 3, "",
                "YAML tag '!!binary'");
  // on a list element and on a key
  ExpectRefused("cameras:\n  - !cam {name: c}\n", 2, "", "YAML tag '!cam'");
  ExpectRefused("!!str seed: 3\n", 1, "", "YAML tag '!!str'");
  // a tag in a verbatim form, and in an aliased anchor
  ExpectRefused("seed: !<tag:example.com,2000:x> 3\n", 1, "", "YAML tag 'tag:example.com,2000:x'");
}

TEST_F(WorldNonsenseTest, QuotedValuesStillFailAsStringsNotAsTags) {
  ExpectRefused("duration_sec: \"1\"\n", 1, "duration_sec", "expected a number");
  EXPECT_NO_THROW(ParseWorld("output: {dir: 'out'}\nseed: 3\n", world_));
}

TEST_F(WorldNonsenseTest, AdversityPresetFilesRefuseTags) {
  const std::string presets =
      dir_.Write("presets.yaml", "presets:\n  foggy:\n    fog: !!map {density_per_m: 0.01}\n");
  try {
    LoadAdversityPresetFile(presets);
    ADD_FAILURE() << "no ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.file(), presets);
    EXPECT_EQ(e.line(), 3);
    EXPECT_NE(std::string(e.what()).find("YAML tag '!!map'"), std::string::npos) << e.what();
  }
}

TEST_F(WorldNonsenseTest, FieldOfViewHasALowerBound) {
  // 1e-300 deg: fx = 2.75e303, every ray the optical axis
  ExpectRefused("cameras:\n  - name: c\n    fovy_deg: 1e-300\n", 3, "cameras[0].fovy_deg",
                "got 1e-300; expected [0.1, 179)");
  ExpectRefused("cameras:\n  - name: c\n    fovy_deg: 0.05\n", 3, "cameras[0].fovy_deg",
                "expected [0.1, 179)");
  EXPECT_NO_THROW(
      ParseWorld("cameras:\n  - {name: c, fovy_deg: 0.1, width: 64, height: 48}\n", world_));
  EXPECT_NO_THROW(ParseWorld("cameras:\n  - {name: c, fovy_deg: 170}\n", world_));
  // square pixels: fovy 60 on a 16384 x 16 line stretches the horizontal view to 179.8 deg
  ExpectRefused("cameras:\n  - {name: c, fovy_deg: 60, width: 16384, height: 16}\n", 2,
                "cameras[0].fovy_deg", "horizontal field of view reaches");
  // and 0.1 deg on a 16 x 1024 portrait image makes the horizontal view 0.0016 deg
  ExpectRefused("cameras:\n  - {name: c, fovy_deg: 0.1, width: 16, height: 1024}\n", 2,
                "cameras[0].fovy_deg", "horizontal field of view is");
}

TEST_F(WorldNonsenseTest, FocalLengthsAndPrincipalPointsAreBoundedByTheImage) {
  // fx = 1e308 px: a field of view of 1e-302 deg
  ExpectRefused(
      "cameras:\n  - name: c\n    width: 64\n    height: 48\n"
      "    intrinsics: {fx: 1e308, fy: 1e308}\n",
      5, "cameras[0].intrinsics", "deg (fx 1e+308 for 64 px); expected at least 0.1 deg");
  ExpectRefused(
      "cameras:\n  - name: c\n    width: 64\n    height: 48\n"
      "    intrinsics: {fx: 60, fy: 1e6}\n",
      5, "cameras[0].intrinsics", "the vertical field of view is");
  // the principal point 1e6 px off a 64 px image (the rays stay within 89.5 deg: fx is large)
  ExpectRefused(
      "cameras:\n  - name: c\n    width: 64\n    height: 48\n"
      "    intrinsics: {fx: 30000, fy: 30000, cx: 1e6, cy: 24}\n",
      5, "cameras[0].intrinsics", "cx is 1e+06 for 64 px; expected [-640, 704]");
  // off-centre crops near the image stay fine, as does the narrowest accepted view
  EXPECT_NO_THROW(
      ParseWorld("cameras:\n  - name: c\n    width: 64\n    height: 48\n"
                 "    intrinsics: {fx: 36000, fy: 27000, cx: -200, cy: 300}\n",
                 world_));
}

TEST_F(WorldNonsenseTest, OverlongNamesAreRefusedWithTheLineAndABoundedEcho) {
  const std::string huge(100000, 'a');
  std::string what =
      ExpectRefused("duration_sec: 1\ncameras:\n  - name: " + huge + "\n", 3, "cameras[0].name",
                    "a name of 100000 characters ('aaaaaaaaaaaaaaaa...'); expected "
                    "at most 64 characters");
  EXPECT_LT(what.size(), 400u) << what.substr(0, 1000);
  const std::string max(kMaxNameLength, 'c');
  EXPECT_NO_THROW(ParseWorld("cameras:\n  - name: " + max + "\n", world_));
  const std::string long_name(kMaxNameLength + 1, 'n');
  ExpectRefused("models:\n  - {name: " + long_name + ", file: m.xml}\n", 2, "models[0].name",
                "a name of 65 characters");
  ExpectRefused("lights:\n  - {name: " + long_name + ", type: point, intensity_cd: 10}\n", 2,
                "lights[0].name", "a name of 65 characters");
  ExpectRefused("sensors:\n  - {name: " + long_name + ", type: imu, body: world}\n", 2,
                "sensors[0].name", "a name of 65 characters");
  ExpectRefused("models:\n  - name: m\n    file: m.xml\n    sites:\n      - {name: " + long_name +
                    ", body: b}\n",
                5, "models[0].sites[0].name", "a name of 65 characters");
  ExpectRefused("semantic_classes:\n  - {name: " + long_name + ", id: 1, bodies: [\"*\"]}\n", 2,
                "semantic_classes[0].name", "a name of 65 characters");
  ExpectRefused("effects:\n  - {name: " + long_name + ", type: fog}\n", 2, "effects[0].name",
                "a name of 65 characters");
  // characters other than letters, digits, '_', '-' are quoted at most 32 bytes long
  what = ExpectRefused("cameras:\n  - name: \"" + std::string(60, 'x') + "!\"\n", 2,
                       "cameras[0].name", "'xxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxx...' has characters");
}

TEST_F(WorldNonsenseTest, SensorNamesCannotBeDotsOrControlCharacters) {
  ExpectRefused("sensors:\n  - {name: '..', type: imu, body: world}\n", 2, "sensors[0].name",
                "not '.' or '..'");
  ExpectRefused("sensors:\n  - {name: \"a\\x01b\", type: imu, body: world}\n", 2, "sensors[0].name",
                "control characters");
}

TEST_F(WorldNonsenseTest, LightLevelsStayWithinFloats) {
  // 1e308 became infinity in the renderer's 32-bit floats
  ExpectRefused(
      "lights:\n  - {name: s, type: sun, direction: [0, 0, -1], illuminance_lux: 1e308}\n", 2,
      "lights[0].illuminance_lux", "got 1e+308; expected (0, 1e+06]");
  ExpectRefused("lights:\n  - {name: l, type: point, intensity_cd: 1e308}\n", 2,
                "lights[0].intensity_cd", "expected (0, 1e+09]");
  ExpectRefused("lights:\n  - {name: l, type: point, power_w: 1e308}\n", 2, "lights[0].power_w",
                "expected (0, 1e+07]");
  ExpectRefused("lights:\n  - {name: l, type: point, intensity_cd: 10, radius_m: 1e308}\n", 2,
                "lights[0].radius_m", "expected [0, 1e+05]");
  ExpectRefused("sky: {zenith_luminance_cd_m2: 1e308}\n", 1, "sky.zenith_luminance_cd_m2",
                "expected [0, 1e+10]");
  ExpectRefused("sky: {luminance_cd_m2: 1e20}\n", 1, "sky.luminance_cd_m2", "expected [0, 1e+10]");
  EXPECT_NO_THROW(ParseWorld(
      "lights:\n  - {name: s, type: sun, direction: [0, 0, -1], illuminance_lux: 120000}\n"
      "  - {name: l, type: spot, direction: [0, 0, -1], intensity_cd: 1e7}\n",
      world_));
}

TEST_F(WorldNonsenseTest, CameraSensorValuesAndRotationsAreBounded) {
  const std::string cam = "cameras:\n  - name: c\n";
  // an exposure of 1e308 s waited for an end snapshot that never came
  ExpectRefused(cam + "    exposure_time_sec: 1e308\n", 3, "cameras[0].exposure_time_sec",
                "camera 'c': got 1e+308; expected [0, 60] (seconds)");
  ExpectRefused(cam + "    rolling_shutter_line_time_sec: 5\n", 3,
                "cameras[0].rolling_shutter_line_time_sec", "expected [0, 0.01] (seconds per row)");
  ExpectRefused(cam + "    noise: {iso: 1e308}\n", 3, "cameras[0].noise.iso",
                "expected (0, 1e+07] (ISO)");
  ExpectRefused(cam + "    noise: {full_well_e: 1e-300}\n", 3, "cameras[0].noise.full_well_e",
                "expected [1, 1e+09] (electrons)");
  // a baseline of 1e308 m put the right camera's rays at infinity
  ExpectRefused(cam + "    stereo: {baseline_m: 1e308}\n", 3, "cameras[0].stereo.baseline_m",
                "expected (0, 100] (m)");
  ExpectRefused("cameras:\n  - {name: c, pose: {rpy_deg: [0, 0, 1e308]}}\n", 2,
                "cameras[0].pose.rpy_deg",
                "component 2 is 1e+308; expected each of the 3 numbers "
                "in [-360, 360]");
  EXPECT_NO_THROW(
      ParseWorld("cameras:\n  - {name: c, pose: {rpy_deg: [-360, 0, 360]}, exposure_time_sec: 30, "
                 "noise: {iso: 3200}, stereo: {baseline_m: 0.12}}\n",
                 world_));
}

TEST_F(WorldNonsenseTest, SensorNoiseAndRecordFileAreChecked) {
  ExpectRefused(
      "sensors:\n  - name: i\n    type: imu\n    body: world\n"
      "    noise: {accel_noise_density: 1e308}\n",
      5, "sensors[0].noise.accel_noise_density", "expected a noise value >= 0 and <= 1000");
  // `record: {file: ""}` silently recorded nothing
  ExpectRefused("record: {file: \"\"}\n", 1, "record.file",
                "empty; expected a file name ending in .plog");
}

TEST(NameLimits, ExcerptCutsAtACharacterBoundaryAndEscapes) {
  EXPECT_EQ(Excerpt("short"), "short");
  EXPECT_EQ(Excerpt(std::string(40, 'z'), 8), "zzzzzzzz...");
  EXPECT_EQ(Excerpt("a\nb"), "a\\x0ab");
  // "é" is two bytes: a cut inside it moves back to its start
  EXPECT_EQ(Excerpt("abc\xc3\xa9xyz", 4), "abc...");
  EXPECT_FALSE(NameLengthProblem(std::string(64, 'a')));
  ASSERT_TRUE(NameLengthProblem(std::string(65, 'a')));
}

}  // namespace
}  // namespace penumbra
