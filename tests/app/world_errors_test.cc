// errors found by a stage after the world file was loaded (scene lights, bodies, materials,
// MJCF cameras, output folder) still name the world file and the line of the key; the empty
// world `{}` runs.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "common/temp_dir.h"
#include "penumbra/run/runner.h"
#include "penumbra/core/error.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

constexpr char kBoxMjcf[] = R"(
<mujoco model="box">
  <worldbody>
    <geom name="floor" type="plane" size="3 3 0.1"/>
    <body name="box" pos="0 0 0.5">
      <freejoint/>
      <geom type="box" size="0.1 0.1 0.1"/>
    </body>
  </worldbody>
</mujoco>)";

class WorldErrorsTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_.Write("box.xml", kBoxMjcf); }

  // runs a world of the box model plus `extra` and returns the ConfigError it raised
  ConfigError RunExpectingError(const std::string& extra) {
    const std::string world = dir_.Write("world.yaml",
                                         "duration_sec: 0.02\n"
                                         "models:\n"
                                         "  - {name: m, file: box.xml}\n" +
                                             extra);
    RunOptions options;
    options.progress = false;
    try {
      WorldConfig w = LoadWorldFile(world);
      // a fresh folder per run (a failed run may leave composed.xml behind)
      if (w.output_dir == "out")
        options.out_dir = (dir_.path() / ("out" + std::to_string(runs_++))).string();
      RunWorld(w, options);
    } catch (const ConfigError& e) {
      return e;
    }
    ADD_FAILURE() << "no ConfigError for:\n" << extra;
    return ConfigError("", 0, "", "");
  }

  void ExpectPlaced(const std::string& extra, int line, const std::string& key,
                    const std::string& text) {
    const ConfigError e = RunExpectingError(extra);
    const std::string what = e.what();
    EXPECT_EQ(e.file(), (dir_.path() / "world.yaml").string()) << what;
    EXPECT_EQ(e.line(), line) << what;
    EXPECT_EQ(e.key(), key) << what;
    EXPECT_NE(what.find(text), std::string::npos) << what;
    EXPECT_EQ(what.find("<command line>"), std::string::npos) << what;
  }

  testing::TempDir dir_;
  int runs_ = 0;
};

TEST_F(WorldErrorsTest, UnknownLightOfALightEvent) {
  ExpectPlaced("effects:\n  - name: flick\n    type: light_event\n    light: nolight\n", 7,
               "effects[0].light", "no scene light named 'nolight'");
}

TEST_F(WorldErrorsTest, UnknownBodyOfAFlashlight) {
  ExpectPlaced("effects:\n  - name: f\n    type: flashlight\n    attach: m/nobody\n", 7,
               "effects[0].attach", "no body named 'm/nobody'");
}

TEST_F(WorldErrorsTest, UnknownBodyOfACameraAndALight) {
  ExpectPlaced("cameras:\n  - name: c\n    attach: m/nobody\n", 6, "cameras[0].attach",
               "no body named 'm/nobody'");
  ExpectPlaced("lights:\n  - name: l\n    type: point\n    attach: m/nobody\n    intensity_cd: 1\n",
               7, "lights[0].attach", "no body named 'm/nobody'");
}

TEST_F(WorldErrorsTest, UnknownMaterialAndMjcfCamera) {
  ExpectPlaced("materials:\n  m/nomat: {roughness: 0.5}\n", 5, "materials.m/nomat",
               "no MJCF material");
  ExpectPlaced("mjcf_cameras:\n  overrides:\n    m/nocam: {width: 64}\n", 6,
               "mjcf_cameras.overrides.m/nocam", "no MJCF camera");
}

TEST_F(WorldErrorsTest, OutputFolderThatCannotBeMade) {
  ExpectPlaced("output:\n  dir: /dev/null/x\n", 5, "output.dir", "cannot be created");
}

TEST_F(WorldErrorsTest, ARunRefusedDuringSetUpLeavesTheFolderAsItFoundIt) {
  const std::string world = dir_.Write("world.yaml",
                                       "duration_sec: 0.02\n"
                                       "models:\n"
                                       "  - {name: m, file: box.xml}\n"
                                       "cameras:\n"
                                       "  - {name: c, attach: m/nobody}\n");
  RunOptions options;
  options.progress = false;
  // a new folder is removed again; an existing empty one is emptied again
  for (const fs::path& out : {dir_.path() / "new_out", dir_.path() / "empty_out"}) {
    if (out.filename() == "empty_out") fs::create_directories(out);
    options.out_dir = out.string();
    for (int attempt = 0; attempt < 2; ++attempt) {
      try {
        RunWorld(LoadWorldFile(world), options);
        ADD_FAILURE() << "expected a ConfigError";
      } catch (const ConfigError& e) {
        // the same error both times: not "is not empty" the second time
        EXPECT_EQ(e.key(), "cameras[0].attach") << e.what();
      }
    }
    if (out.filename() == "new_out") {
      EXPECT_FALSE(fs::exists(out));
    } else {
      EXPECT_TRUE(fs::is_empty(out));
    }
  }
}

TEST_F(WorldErrorsTest, EmptyWorldRuns) {
  const std::string world = dir_.Write("empty.yaml", "{}\n");
  WorldConfig w = LoadWorldFile(world);
  w.duration_sec = 0.05;
  RunOptions options;
  options.progress = false;
  options.out_dir = (dir_.path() / "empty_out").string();
  const RunSummary s = RunWorld(w, options);
  EXPECT_NEAR(s.sim_time_sec, 0.05, 1e-9);
  EXPECT_GT(s.physics_steps, 0);
  EXPECT_TRUE(s.frames_per_camera.empty());
  EXPECT_TRUE(fs::exists(dir_.path() / "empty_out" / "run.json"));
}

}  // namespace
}  // namespace penumbra
