// the output-folder rule: empty or new, or --force over an earlier run's outputs only;
// links are never followed or removed.

#include "penumbra/output/output_folder.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "common/temp_dir.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

// the files of an earlier run, as `penumbra run` writes them
void WriteEarlierRun(const testing::TempDir& dir) {
  for (const char* f : {"out/run.json",
                        "out/composed.xml",
                        "out/trajectory.csv",
                        "out/camera_info.yaml",
                        "out/camera_info.json",
                        "out/semantic_classes.json",
                        "out/rig.json",
                        "out/cam/frames.csv",
                        "out/cam/intrinsics.json",
                        "out/cam/rgb/000000.png",
                        "out/cam/depth/000000.png",
                        "out/cam/segmentation/000000.png",
                        "out/cam/normals/000001.png",
                        "out/scene/overhead/rgb/000002.png",
                        "out/scene/overhead/frames.csv",
                        "out/lidar/top/index.csv",
                        "out/lidar/top/scan_000003.pcd",
                        "out/imu/imu.csv",
                        "out/imu/imu_truth.csv",
                        "out/sensors/joints.csv",
                        "out/ground_truth/gt.csv",
                        "out/ground_truth/gt_contacts.csv",
                        "out/environments/outdoor-6df88287a734f8a6.xml",
                        "out/environments/outdoor-terrain-c52f209b89af0ab6.hfield",
                        "out/cam/rgb/.000001.png.tmp-42-7"})
    dir.Write(f, "x");
}

std::string Message(const fs::path& out, bool force) {
  try {
    PrepareOutputFolder(out, force);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(OutputFolderTest, NewAndEmptyFoldersAreUsed) {
  testing::TempDir dir;
  PrepareOutputFolder(dir.path() / "a" / "b", false);
  EXPECT_TRUE(fs::is_directory(dir.path() / "a" / "b"));
  PrepareOutputFolder(dir.path() / "a" / "b", false);  // empty
  dir.Write("file", "x");
  EXPECT_NE(Message(dir.path() / "file", true).find("is not a folder"), std::string::npos);
}

TEST(OutputFolderTest, NonEmptyFolderIsRefusedWithoutForce) {
  testing::TempDir dir;
  WriteEarlierRun(dir);
  const std::string m = Message(dir.path() / "out", false);
  EXPECT_NE(m.find("--out"), std::string::npos) << m;
  EXPECT_NE(m.find("is not empty"), std::string::npos) << m;
  EXPECT_NE(m.find("'camera_info.json'"), std::string::npos) << m;
  EXPECT_NE(m.find("--force"), std::string::npos) << m;
  EXPECT_TRUE(fs::exists(dir.path() / "out" / "cam" / "rgb" / "000000.png"));
}

TEST(OutputFolderTest, ForceClearsAnEarlierRun) {
  testing::TempDir dir;
  WriteEarlierRun(dir);
  EXPECT_TRUE(ForeignOutputEntries(dir.path() / "out").empty());
  PrepareOutputFolder(dir.path() / "out", true);
  EXPECT_TRUE(fs::is_empty(dir.path() / "out"));
}

TEST(OutputFolderTest, ForceRefusesToDeleteAnythingElseAndNamesIt) {
  testing::TempDir dir;
  WriteEarlierRun(dir);
  dir.Write("out/notes.txt", "mine");
  dir.Write("out/cam/rgb/holiday.jpg", "mine");
  dir.Write("out/imu/readme.md", "mine");
  const std::string m = Message(dir.path() / "out", true);
  EXPECT_NE(m.find("'cam/rgb/holiday.jpg', 'imu/readme.md', 'notes.txt'"), std::string::npos) << m;
  EXPECT_NE(m.find("did not write"), std::string::npos) << m;
  // nothing was removed
  EXPECT_TRUE(fs::exists(dir.path() / "out" / "notes.txt"));
  EXPECT_TRUE(fs::exists(dir.path() / "out" / "run.json"));
  EXPECT_TRUE(fs::exists(dir.path() / "out" / "cam" / "rgb" / "000000.png"));
}

TEST(OutputFolderTest, LinksAreNeverFollowedOrRemoved) {
  testing::TempDir dir;
  WriteEarlierRun(dir);
  const fs::path victim = dir.Write("victim/run.json", "precious");
  dir.Write("victim/000000.png", "precious");
  fs::remove(dir.path() / "out" / "run.json");
  fs::create_symlink(victim, dir.path() / "out" / "run.json");
  fs::create_directory_symlink(dir.path() / "victim", dir.path() / "out" / "cam" / "depth2");
  const std::string m = Message(dir.path() / "out", true);
  EXPECT_NE(m.find("'cam/depth2 (a symbolic link)', 'run.json (a symbolic link)'"),
            std::string::npos)
      << m;
  EXPECT_TRUE(fs::is_symlink(dir.path() / "out" / "run.json"));
  EXPECT_EQ(fs::file_size(victim), 8u);
  EXPECT_TRUE(fs::exists(dir.path() / "victim" / "000000.png"));
}

// a set-up that fails leaves the folder as it found it: a created one is removed, an empty
// one emptied; once dismissed, what the run wrote stays
TEST(OutputFolderTest, SetupRollbackLeavesTheFolderAsFoundUnlessDismissed) {
  testing::TempDir dir;
  const fs::path created = dir.path() / "new";
  const fs::path existing = dir.path() / "old";
  fs::create_directories(existing);
  PrepareOutputFolder(created, false);
  PrepareOutputFolder(existing, false);
  {
    SetupRollback a(created, true), b(existing, false);
    std::ofstream(created / "run.json") << "{}";
    fs::create_directories(existing / "cam" / "rgb");
    std::ofstream(existing / "composed.xml") << "<mujoco/>";
  }
  EXPECT_FALSE(fs::exists(created));
  ASSERT_TRUE(fs::is_directory(existing));
  EXPECT_TRUE(fs::is_empty(existing));
  {
    SetupRollback kept(existing, false);
    std::ofstream(existing / "run.json") << "{}";
    kept.Dismiss();
  }
  EXPECT_TRUE(fs::is_regular_file(existing / "run.json"));
}

}  // namespace
}  // namespace penumbra
