// reading a run folder's files without following links out of it (dataset/run_file.h): links
// at the end or in the middle of a path, "..", FIFOs and oversized files are refused with a
// message naming the file; plain files and folders are read.

#include "penumbra/dataset/run_file.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "common/temp_dir.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

// the message of the ConfigError `f` throws ("" when it throws none)
template <typename F>
std::string RunFileError(F&& f) {
  try {
    f();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

class RunFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    run_ = tmp_.path() / "run";
    fs::create_directories(run_ / "cam" / "rgb");
    std::ofstream(run_ / "cam" / "rgb" / "000000.png", std::ios::binary) << "frame";
    std::ofstream(tmp_.path() / "secret.txt") << "secret";
  }
  testing::TempDir tmp_;
  fs::path run_;
};

TEST_F(RunFileTest, ReadsPlainFilesAndTellsEntries) {
  EXPECT_EQ(ReadRunFile(run_, "cam/rgb/000000.png"), "frame");
  EXPECT_EQ(StatRunEntry(run_, "cam/rgb"), RunEntry::kFolder);
  EXPECT_EQ(StatRunEntry(run_, "cam/rgb/000000.png"), RunEntry::kFile);
  EXPECT_EQ(StatRunEntry(run_, "cam/depth"), RunEntry::kMissing);
  // the run folder itself may be reached through a link (the user named it)
  fs::create_directory_symlink(run_, tmp_.path() / "run_link");
  EXPECT_EQ(ReadRunFile(tmp_.path() / "run_link", "cam/rgb/000000.png"), "frame");
}

TEST_F(RunFileTest, RefusesLinksBelowTheRunFolder) {
  fs::create_symlink(tmp_.path() / "secret.txt", run_ / "cam" / "rgb" / "000001.png");
  std::string e = RunFileError([&] { ReadRunFile(run_, "cam/rgb/000001.png"); });
  EXPECT_NE(e.find("000001.png"), std::string::npos) << e;
  EXPECT_NE(e.find("symbolic link"), std::string::npos) << e;
  e = RunFileError([&] { StatRunEntry(run_, "cam/rgb/000001.png"); });
  EXPECT_NE(e.find("symbolic link"), std::string::npos) << e;
  // a linked folder in the middle of the path
  fs::create_directories(tmp_.path() / "other");
  std::ofstream(tmp_.path() / "other" / "000000.png") << "other";
  fs::create_directory_symlink(tmp_.path() / "other", run_ / "cam" / "depth");
  e = RunFileError([&] { ReadRunFile(run_, "cam/depth/000000.png"); });
  EXPECT_NE(e.find("cam/depth"), std::string::npos) << e;
  EXPECT_NE(e.find("symbolic link"), std::string::npos) << e;
  e = RunFileError([&] { StatRunEntry(run_, "cam/depth"); });
  EXPECT_NE(e.find("symbolic link"), std::string::npos) << e;
}

TEST_F(RunFileTest, RefusesPathsOutOfTheFolderFifosAndOversizedFiles) {
  for (const char* bad : {"../secret.txt", "cam/../../secret.txt", "/etc/passwd", ""}) {
    const std::string e = RunFileError([&] { ReadRunFile(run_, bad); });
    EXPECT_NE(e.find("not a path inside the run folder"), std::string::npos) << bad << ": " << e;
  }
  EXPECT_FALSE(IsPlainRelativePath("cam/./x"));
  EXPECT_TRUE(IsPlainRelativePath("cam/right/rgb"));
  // a FIFO would block a reader forever: refused at once
  ASSERT_EQ(mkfifo((run_ / "cam" / "frames.csv").c_str(), 0600), 0);
  std::string e = RunFileError([&] { ReadRunFile(run_, "cam/frames.csv"); });
  EXPECT_NE(e.find("not a regular file"), std::string::npos) << e;
  EXPECT_EQ(StatRunEntry(run_, "cam/frames.csv"), RunEntry::kOther);
  e = RunFileError([&] { ReadRunFile(run_, "cam/rgb/000000.png", 4); });
  EXPECT_NE(e.find("5 bytes; expected at most 4"), std::string::npos) << e;
  e = RunFileError([&] { ReadRunFile(run_, "cam/rgb/missing.png"); });
  EXPECT_NE(e.find("missing"), std::string::npos) << e;
}

}  // namespace
}  // namespace penumbra
