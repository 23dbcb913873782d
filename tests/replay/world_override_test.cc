// ApplyWorldOverride: a replay's --world fragment replaces the recorded world's visual keys,
// refuses keys that change physics (naming the key and line), reads its values as a world file
// of the recorded models, and errors found later name the override's lines.
#include "penumbra/replay/world_override.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "common/temp_dir.h"
#include "penumbra/core/error.h"
#include "penumbra/world/yaml_reader.h"

namespace penumbra {
namespace {

const std::string kOverrideWorlds = std::string(PENUMBRA_SOURCE_DIR) + "/worlds/";

WorldConfig Recorded() { return LoadWorldFile(kOverrideWorlds + "sensors.yaml"); }

ConfigError OverrideError(const std::string& text, const testing::TempDir& dir) {
  const std::string path = dir.Write("override.yaml", text);
  try {
    ApplyWorldOverride(Recorded(), path);
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.file(), path) << e.what();
    return e;
  }
  ADD_FAILURE() << "no error for:\n" << text;
  return ConfigError("", 0, "", "");
}

TEST(WorldOverride, KeysThatChangePhysicsAreRefusedNamingKeyAndLine) {
  testing::TempDir dir;
  ConfigError e = OverrideError("sky: {type: uniform}\nphysics: {timestep_sec: 0.001}\n", dir);
  EXPECT_EQ(e.line(), 2);
  EXPECT_EQ(e.key(), "physics");
  EXPECT_NE(e.problem().find("changes the recorded physics"), std::string::npos) << e.what();
  e = OverrideError("robots: []\n", dir);
  EXPECT_EQ(e.key(), "robots");
  EXPECT_NE(e.problem().find("changes the recorded models"), std::string::npos) << e.what();
  e = OverrideError("models: []\n", dir);
  EXPECT_EQ(e.key(), "models");
  e = OverrideError("# a comment\n\nduration_sec: 5\n", dir);
  EXPECT_EQ(e.line(), 3);
  EXPECT_NE(e.problem().find("--from SEC / --to SEC"), std::string::npos) << e.what();
  e = OverrideError("record: {file: x.plog}\n", dir);
  EXPECT_EQ(e.key(), "record");
  EXPECT_NE(e.problem().find("cannot be replaced in a replay; expected some of: cameras"),
            std::string::npos)
      << e.what();
}

TEST(WorldOverride, ADocumentThatIsNotABlockMappingIsRefused) {
  testing::TempDir dir;
  EXPECT_NE(std::string(OverrideError("{sky: {type: uniform}}\n", dir).what())
                .find("expected a world-file fragment"),
            std::string::npos);
  EXPECT_NE(std::string(OverrideError("- a\n- b\n", dir).what()).find("block mapping"),
            std::string::npos);
  EXPECT_NE(std::string(OverrideError("", dir).what()).find("block mapping"), std::string::npos);
  try {
    ApplyWorldOverride(Recorded(), dir.str() + "/missing.yaml");
    ADD_FAILURE();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("not found"), std::string::npos);
  }
}

TEST(WorldOverride, ValuesAreReadAsAWorldFileWithItsOwnLines) {
  testing::TempDir dir;
  ConfigError e = OverrideError(
      "cameras:\n"
      "  - name: wide\n"
      "    attach: go1/camera_mount\n"
      "    width: -4\n",
      dir);
  EXPECT_EQ(e.line(), 4);
  EXPECT_EQ(e.key(), "cameras[0].width");
  // names are checked against the recorded models
  e = OverrideError(
      "cameras:\n"
      "  - name: wide\n"
      "    attach: rover/base\n",
      dir);
  EXPECT_EQ(e.line(), 3);
  EXPECT_NE(e.problem().find("unknown model 'rover'; expected one of: go1, room"),
            std::string::npos)
      << e.what();
  e = OverrideError("lights:\n  - name: l\n    type: point\n    bogus: 1\n", dir);
  EXPECT_EQ(e.line(), 4);
}

TEST(WorldOverride, ReplacesOnlyTheKeysItNames) {
  testing::TempDir dir;
  const std::string path = dir.Write("override.yaml",
                                     "cameras:\n"
                                     "  - name: front\n"
                                     "    attach: go1/camera_mount\n"
                                     "    width: 320\n"
                                     "    height: 240\n"
                                     "  - name: rear\n"
                                     "    attach: go1/trunk\n"
                                     "    pose: {rpy_deg: [0, 0, 180]}\n"
                                     "sky: {type: uniform, luminance_cd_m2: 50}\n"
                                     "seed: 99\n");
  const WorldConfig recorded = Recorded();
  WorldOverride applied;
  const WorldConfig w = ApplyWorldOverride(recorded, path, &applied);
  EXPECT_EQ(applied.file, path);
  EXPECT_EQ(applied.keys, (std::vector<std::string>{"cameras", "sky", "seed"}));
  ASSERT_EQ(w.cameras.size(), 2u);
  EXPECT_EQ(w.cameras[0].width, 320);
  EXPECT_EQ(w.cameras[1].name, "rear");
  EXPECT_EQ(w.sky.type, Sky::Type::kUniform);
  EXPECT_EQ(w.sky.luminance_cd_m2, 50);
  EXPECT_EQ(w.seed, 99u);
  EXPECT_EQ(w.render.seed, 99u);
  // the rest as recorded
  EXPECT_EQ(w.file, recorded.file);
  EXPECT_EQ(w.lights.size(), recorded.lights.size());
  EXPECT_EQ(w.materials.size(), recorded.materials.size());
  EXPECT_EQ(w.sensors.size(), recorded.sensors.size());
  ASSERT_EQ(w.models.size(), recorded.models.size());
  EXPECT_EQ(w.models[0].controller.type, recorded.models[0].controller.type);
  EXPECT_EQ(w.timestep_sec, recorded.timestep_sec);
}

TEST(WorldOverride, SensorsReplaceTheTopLevelListAndKeepTheRobotsOwn) {
  testing::TempDir dir;
  const std::string path = dir.Write("override.yaml",
                                     "sensors:\n"
                                     "  - name: truth2\n"
                                     "    type: ground_truth\n"
                                     "    bodies: [go1/trunk]\n");
  const WorldConfig w = ApplyWorldOverride(Recorded(), path);
  std::vector<std::string> names;
  for (const SensorConfig& s : w.sensors) names.push_back(s.name);
  // the robot's IMU (listed under robots[0]) stays; top, joints, truth are replaced
  EXPECT_EQ(names, (std::vector<std::string>{"truth2", "trunk_imu"})) << names.size();
  // a top-level sensor with the name of a robot's sensor is refused
  const std::string dup = dir.Write("dup.yaml",
                                    "sensors:\n"
                                    "  - name: trunk_imu\n"
                                    "    type: ground_truth\n"
                                    "    bodies: [go1/trunk]\n");
  EXPECT_THROW(ApplyWorldOverride(Recorded(), dup), ConfigError);
}

TEST(WorldOverride, LaterErrorsNameTheOverrideLineUnderItsKeys) {
  testing::TempDir dir;
  const std::string path = dir.Write("override.yaml",
                                     "sky: {type: uniform}\n"
                                     "cameras:\n"
                                     "  - name: a\n"
                                     "    attach: go1/trunk\n"
                                     "  - name: b\n"
                                     "    attach: go1/no_such_body\n");
  const WorldConfig recorded = Recorded();
  WorldOverride applied;
  const WorldConfig w = ApplyWorldOverride(recorded, path, &applied);
  const ConfigError in_override =
      LocateReplayError(w, applied, ConfigError("", 0, "cameras[1].attach", "no body"));
  EXPECT_EQ(in_override.file(), path);
  EXPECT_EQ(in_override.line(), 6);
  const ConfigError in_world =
      LocateReplayError(w, applied, ConfigError("", 0, "lights[1].name", "no light"));
  EXPECT_EQ(in_world.file(), recorded.file);
  EXPECT_EQ(in_world.line(), recorded.lines->Find("lights[1].name"));
  EXPECT_GT(in_world.line(), 0);
}

TEST(WorldOverride, ErrorsOfTheRecordedModelsNameTheRecordedWorldNotALinePastTheFragment) {
  // the fragment is read with the recorded models appended after its last line: a recorded
  // model file that has gone was reported at line 5 of this 3-line override
  testing::TempDir dir;
  const std::string model = dir.Write(
      "m.xml",
      "<mujoco><worldbody><body name=\"b\"><geom size=\"0.1\"/></body></worldbody></mujoco>");
  const std::string world =
      dir.Write("world.yaml", "duration_sec: 1\nmodels:\n  - name: box\n    file: m.xml\n");
  const WorldConfig recorded = LoadWorldFile(world);
  std::filesystem::remove(model);
  const std::string path = dir.Write("override.yaml", "sky: {type: uniform}\n# one\n# two\n");
  try {
    ApplyWorldOverride(recorded, path);
    ADD_FAILURE() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.file(), world) << e.what();
    EXPECT_EQ(e.line(), 4) << e.what();
    EXPECT_EQ(e.key(), "models[0].file") << e.what();
    EXPECT_NE(e.problem().find("file not found"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace penumbra
