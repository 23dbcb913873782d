// one run per output folder and per run log (output/output_lock.h): a second run into a folder
// or log a live run holds fails at start naming that run's PID, and --force never empties the
// folder or truncates the log of a live run. flock(2) locks conflict between two opens in one
// process too, so "another run" is played here by a lock this test holds.

#include "penumbra/output/output_lock.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "common/temp_dir.h"
#include "penumbra/core/error.h"
#include "penumbra/output/output_folder.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

std::string Pid() { return "PID " + std::to_string(::getpid()); }

template <typename F>
std::string ErrorOf(F&& f) {
  try {
    f();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(OutputLockTest, ASecondRunIntoAFolderFailsNamingTheFirstRunsPid) {
  testing::TempDir dir;
  const fs::path out = dir.path() / "out";
  const OutputLock first = PrepareOutputFolder(out, false);
  ASSERT_TRUE(first.held());
  const std::string e = ErrorOf([&] { PrepareOutputFolder(out, false); });
  EXPECT_NE(e.find("--out"), std::string::npos) << e;
  EXPECT_NE(e.find("is in use by another run (" + Pid() + ")"), std::string::npos) << e;
}

TEST(OutputLockTest, ForceNeverEmptiesAFolderALiveRunHolds) {
  testing::TempDir dir;
  const fs::path out = dir.path() / "out";
  const OutputLock live = PrepareOutputFolder(out, false);
  dir.Write("out/run.json", "{}");
  dir.Write("out/cam/rgb/000000.png", "frame");
  const std::string e = ErrorOf([&] { PrepareOutputFolder(out, true, "output.dir"); });
  EXPECT_NE(e.find("output.dir"), std::string::npos) << e;
  EXPECT_NE(e.find(Pid()), std::string::npos) << e;
  EXPECT_NE(e.find("--force never removes the outputs of a running run"), std::string::npos) << e;
  EXPECT_EQ(ReadAll(out / "run.json"), "{}");
  EXPECT_EQ(ReadAll(out / "cam/rgb/000000.png"), "frame");
}

TEST(OutputLockTest, TheLockEndsWithItsHolder) {
  testing::TempDir dir;
  const fs::path out = dir.path() / "out";
  { const OutputLock a = PrepareOutputFolder(out, false); }
  dir.Write("out/run.json", "{}");
  // the first run has ended: --force replaces its outputs
  const OutputLock b = PrepareOutputFolder(out, true);
  EXPECT_TRUE(b.held());
  EXPECT_FALSE(fs::exists(out / "run.json"));
}

TEST(OutputLockTest, ARunLogIsNewOrReplacedOnlyWithForceAndNeverWhileARunWritesIt) {
  testing::TempDir dir;
  const std::string log = (dir.path() / "a.plog").string();
  LockedRunLogFile first = OpenRunLogFile(log, false, "--record");
  ASSERT_GE(first.fd.get(), 0);
  EXPECT_TRUE(first.created);
  ASSERT_EQ(::write(first.fd.get(), "PLOG", 4), 4);
  // a second run into the same log, with or without --force, fails naming the first
  for (const bool force : {false, true}) {
    const std::string e = ErrorOf([&] { OpenRunLogFile(log, force, "--record"); });
    EXPECT_NE(e.find("--record"), std::string::npos) << e;
    EXPECT_NE(e.find("is being written by another run (" + Pid() + ")"), std::string::npos) << e;
    EXPECT_EQ(ReadAll(log), "PLOG");
  }
  first.fd = UniqueFd();
  // the first run has ended: an existing log is kept unless the user passes --force
  const std::string e = ErrorOf([&] { OpenRunLogFile(log, false, "--record"); });
  EXPECT_NE(e.find("exists"), std::string::npos) << e;
  EXPECT_NE(e.find("--force"), std::string::npos) << e;
  EXPECT_EQ(ReadAll(log), "PLOG");
  LockedRunLogFile again = OpenRunLogFile(log, true, "--record");
  EXPECT_FALSE(again.created);
  EXPECT_EQ(fs::file_size(log), 0u);
}

TEST(OutputLockTest, ARunLogIsNeverWrittenThroughALinkOrIntoANonFile) {
  testing::TempDir dir;
  dir.Write("victim.txt", "keep");
  const fs::path link = dir.path() / "link.plog";
  fs::create_symlink(dir.path() / "victim.txt", link);
  for (const bool force : {false, true}) {
    const std::string e = ErrorOf([&] { OpenRunLogFile(link.string(), force, "--record"); });
    EXPECT_NE(e.find("symbolic link"), std::string::npos) << e;
  }
  EXPECT_EQ(ReadAll(dir.path() / "victim.txt"), "keep");
  fs::create_directory(dir.path() / "folder.plog");
  const std::string e =
      ErrorOf([&] { OpenRunLogFile((dir.path() / "folder.plog").string(), true, "--record"); });
  EXPECT_NE(e.find("not a regular file"), std::string::npos) << e;
}

}  // namespace
}  // namespace penumbra
