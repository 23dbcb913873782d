// RecordedWorld: the world a log was recorded with, from the header's text at the recorded path
// with the recorded run's seed and command-line flags; ChangedAssets: assets whose content
// changed since the recording.
#include "penumbra/replay/recorded_world.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include "common/temp_dir.h"
#include "common/within_seconds.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

const std::string kWorlds = std::string(PENUMBRA_SOURCE_DIR) + "/worlds/";

TEST(RecordedRunFlags, ReadsTheFlagsThatChangeWhatIsSeen) {
  RecordedRunFlags f = ParseRecordedRunFlags(
      "penumbra run worlds/default.yaml --tier pathtraced --record x.plog --spp 4 "
      "--outputs=rgb,depth --adversity minor --seed 3 --adversity=major");
  EXPECT_EQ(f.adversity, "major");
  EXPECT_EQ(f.tier, "pathtraced");
  EXPECT_EQ(f.samples_per_pixel, 4);
  EXPECT_EQ(f.outputs, "rgb,depth");
  f = ParseRecordedRunFlags("penumbra run worlds/default.yaml --out o");
  EXPECT_EQ(f.adversity, "");
  EXPECT_FALSE(f.tier);
  EXPECT_FALSE(f.samples_per_pixel);
  EXPECT_FALSE(f.outputs);
  // a flag without its value at the end is ignored
  EXPECT_FALSE(ParseRecordedRunFlags("penumbra run w.yaml --tier").tier);
}

TEST(RecordedWorld, TheRecordedTextAtItsRecordedPathWithTheRunsFlags) {
  testing::TempDir dir;
  RunLogHeader h;
  // the recorded text, not today's file: the recorded world had another seed and one camera
  // at 160 x 120; relative model paths resolve against the recorded path's folder
  std::string text = testing::ReadAll(kWorlds + "default.yaml");
  const std::string from = "    width: 640\n    height: 480\n";
  ASSERT_NE(text.find(from), std::string::npos);
  text.replace(text.find(from), from.size(), "    width: 160\n    height: 120\n");
  h.world_file = kWorlds + "default.yaml";
  h.world_text = text + "\nrecord: {file: again.plog}\n";
  h.seed = 12;
  h.command_line = "penumbra run worlds/default.yaml --tier pathtraced --spp 2 --outputs rgb";
  const WorldConfig w = RecordedWorld(h);
  EXPECT_EQ(w.file, h.world_file);
  EXPECT_TRUE(w.record.file.empty());  // a replay writes no run log
  EXPECT_EQ(w.seed, 12u);
  EXPECT_EQ(w.render.seed, 12u);
  ASSERT_EQ(w.cameras.size(), 1u);
  EXPECT_EQ(w.cameras[0].width, 160);
  EXPECT_TRUE(w.cameras[0].outputs[ImageKind::kRgb]);
  EXPECT_FALSE(w.cameras[0].outputs[ImageKind::kDepth]);
  EXPECT_EQ(w.render.tier, RenderSettings::Tier::kPathtraced);
  EXPECT_EQ(w.render.samples_per_pixel, 2);
  ASSERT_EQ(w.models.size(), 2u);
  EXPECT_EQ(w.models[0].file, kWorlds + "models/quadruped.xml");

  // a recorded text that no longer loads names the recorded file and line
  h.world_text = "seed: 1\nrobots:\n  - {name: r, file: models/gone.xml}\n";
  try {
    RecordedWorld(h);
    ADD_FAILURE();
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.file(), h.world_file);
    EXPECT_EQ(e.line(), 3);
  }

  // a bare model run
  RunLogHeader bare;
  bare.model_file = kWorlds + "models/rover.xml";
  bare.seed = 5;
  const WorldConfig b = RecordedWorld(bare);
  ASSERT_EQ(b.models.size(), 1u);
  EXPECT_EQ(b.models[0].file, bare.model_file);
  EXPECT_EQ(b.seed, 5u);
}

TEST(ChangedAssets, NamesAssetsWhoseContentChangedOrIsGone) {
  testing::TempDir dir;
  const std::string same = dir.Write("same.xml", "<mujoco/>");
  const std::string changed = dir.Write("changed.xml", "<mujoco/>");
  RunLogHeader h;
  h.assets = {{"world", dir.str() + "/world.yaml", "00", 0},
              {"model", same, Sha256Hex("<mujoco/>"), 9},
              {"model", changed, Sha256Hex("<mujoco/>"), 9},
              {"mesh", dir.str() + "/gone.stl", Sha256Hex("solid"), 5}};
  dir.Write("changed.xml", "<mujoco><worldbody/></mujoco>");
  const std::vector<std::string> w = ChangedAssets(h);
  ASSERT_EQ(w.size(), 2u);
  EXPECT_NE(w[0].find("model " + changed + " changed since the run was recorded"),
            std::string::npos)
      << w[0];
  EXPECT_NE(w[1].find("mesh " + dir.str() + "/gone.stl cannot be read"), std::string::npos) << w[1];
}

// a log names its assets' paths: a FIFO there blocked replay and --resimulate in open() for
// ever, /dev/zero was hashed for ever; both are named as what they are
TEST(ChangedAssets, AFifoOrADeviceAsAnAssetIsReportedAtOnce) {
  testing::TempDir dir;
  const std::string fifo = (dir.path() / "robot.xml").string();
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  RunLogHeader h;
  h.assets = {{"model", fifo, Sha256Hex("<mujoco/>"), 9},
              {"mesh", "/dev/zero", Sha256Hex("solid"), 5}};
  const testing::WithinResult r = testing::RunWithin(10, [&] {
    const std::vector<std::string> w = ChangedAssets(h);
    return w.size() == 2 && w[0].find("a FIFO") != std::string::npos &&
                   w[1].find("a character device") != std::string::npos
               ? 0
               : 1;
  });
  EXPECT_TRUE(r.finished) << "ChangedAssets blocked on a FIFO or /dev/zero";
  EXPECT_EQ(r.exit_status, 0);
  const std::vector<std::string> w = ChangedAssets(h);
  ASSERT_EQ(w.size(), 2u);
  EXPECT_EQ(w[0], "model " + fifo + " cannot be read any more (" + fifo +
                      ": cannot be read for its content hash: asset file is not a regular file "
                      "(a FIFO); expected a regular file)");
  EXPECT_NE(w[1].find("asset file is not a regular file (a character device)"), std::string::npos)
      << w[1];
}

}  // namespace
}  // namespace penumbra
