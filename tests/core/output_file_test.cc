// crash-safe output files: atomic whole-file writes, whole-row CSVs, no writing through links,
// and what a failed write leaves (injected with RLIMIT_FSIZE and /dev/full, so that no
// mount or full disk is needed).

#include "penumbra/core/output_file.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "common/temp_dir.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

using testing::ReadAll;

std::vector<std::string> Names(const fs::path& dir) {
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(dir)) out.push_back(e.path().filename().string());
  std::sort(out.begin(), out.end());
  return out;
}

// limits the size of any file this process writes to `bytes` while it lives; writes past it
// fail with EFBIG ("File too large") instead of raising SIGXFSZ
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    getrlimit(RLIMIT_FSIZE, &old_);
    old_handler_ = signal(SIGXFSZ, SIG_IGN);
    rlimit r = old_;
    r.rlim_cur = bytes;
    setrlimit(RLIMIT_FSIZE, &r);
  }
  ~FileSizeLimit() {
    setrlimit(RLIMIT_FSIZE, &old_);
    signal(SIGXFSZ, old_handler_);
  }

 private:
  rlimit old_{};
  sighandler_t old_handler_;
};

TEST(WriteFileAtomicTest, WritesAndReplacesWithoutLeavingTemporaries) {
  testing::TempDir dir;
  const fs::path p = dir.path() / "a.json";
  WriteFileAtomic(p, "first");
  EXPECT_EQ(ReadAll(p), "first");
  WriteFileAtomic(p, "second, longer");
  EXPECT_EQ(ReadAll(p), "second, longer");
  EXPECT_EQ(Names(dir.path()), std::vector<std::string>{"a.json"});
}

TEST(WriteFileAtomicTest, FailedWriteKeepsTheOldFileAndRemovesTheTemporary) {
  testing::TempDir dir;
  const fs::path p = dir.path() / "000001.png";
  WriteFileAtomic(p, "old");
  const std::string big(64 * 1024, 'x');
  try {
    const FileSizeLimit limit(4096);
    WriteFileAtomic(p, big);
    FAIL() << "expected an Error";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(p.string()), std::string::npos) << what;
    EXPECT_NE(what.find("File too large"), std::string::npos) << what;
  }
  EXPECT_EQ(ReadAll(p), "old");  // never a truncated file under the final name
  EXPECT_EQ(Names(dir.path()), std::vector<std::string>{"000001.png"});
  // a new file that fails is not created at all (no 0-byte or partial file)
  try {
    const FileSizeLimit limit(4096);
    WriteFileAtomic(dir.path() / "new.png", big);
    FAIL() << "expected an Error";
  } catch (const Error&) {
  }
  EXPECT_EQ(Names(dir.path()), std::vector<std::string>{"000001.png"});
}

TEST(WriteFileAtomicTest, ReplacesALinkInsteadOfWritingThroughIt) {
  testing::TempDir dir;
  const fs::path victim = dir.Write("victim.txt", "keep me");
  fs::create_directories(dir.path() / "out");
  fs::create_symlink(victim, dir.path() / "out" / "run.json");
  WriteFileAtomic(dir.path() / "out" / "run.json", "{}");
  EXPECT_EQ(ReadAll(victim), "keep me");
  EXPECT_FALSE(fs::is_symlink(dir.path() / "out" / "run.json"));
  EXPECT_EQ(ReadAll(dir.path() / "out" / "run.json"), "{}");
}

TEST(WriteFileAtomicTest, TemporaryNamesAreRecognised) {
  EXPECT_TRUE(IsTemporaryOutputName(".000001.png.tmp-123-4"));
  EXPECT_FALSE(IsTemporaryOutputName("000001.png"));
  EXPECT_FALSE(IsTemporaryOutputName(".hidden"));
}

TEST(LineFileTest, WritesWholeRowsAndCutsAFailedWriteBackToTheLastCompleteRow) {
  testing::TempDir dir;
  const fs::path p = dir.path() / "trajectory.csv";
  const std::string row = "12345,0.0020000000000000001,0.5,0.25,1.125\n";
  size_t rows = 0;
  try {
    const FileSizeLimit limit(1000);
    LineFile f(p, 100);  // small buffer: several writes before the limit
    f.Append("step,time_sec,a,b,c\n");
    for (rows = 0; rows < 1000; ++rows) f.Append(row);
    f.Close();
    FAIL() << "expected an Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(p.string()), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("File too large"), std::string::npos) << e.what();
  }
  const std::string text = ReadAll(p);
  ASSERT_FALSE(text.empty());
  EXPECT_LE(text.size(), 1000u);
  EXPECT_EQ(text.back(), '\n');  // the partial row was cut off
  EXPECT_EQ((text.size() - 20) % row.size(), 0u) << text.size();
  EXPECT_GT(text.size(), 500u);  // the rows before the failure were kept
}

TEST(LineFileTest, AFileWithoutACompleteRowIsRemoved) {
  testing::TempDir dir;
  const fs::path p = dir.path() / "imu.csv";
  try {
    const FileSizeLimit limit(10);
    LineFile f(p, 0);
    f.Append("sample,capture_time_sec,delivery_time_sec\n");
    FAIL() << "expected an Error";
  } catch (const Error&) {
  }
  EXPECT_FALSE(fs::exists(p));
}

TEST(LineFileTest, DevFullReportsThePathAndTheReason) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  LineFile f("/dev/full", 0);
  try {
    f.Append("a,b\n");
    FAIL() << "expected an Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot write '/dev/full': No space left on device"),
              std::string::npos)
        << e.what();
  }
  // the error sticks: later appends and Close report it again
  EXPECT_THROW(f.Append("c,d\n"), Error);
  EXPECT_THROW(f.Close(), Error);
  EXPECT_TRUE(fs::exists("/dev/full"));
}

TEST(LineFileTest, RefusesALinkAndRowsWithoutNewline) {
  testing::TempDir dir;
  const fs::path victim = dir.Write("victim.txt", "keep me");
  fs::create_symlink(victim, dir.path() / "frames.csv");
  EXPECT_THROW(LineFile(dir.path() / "frames.csv"), Error);
  EXPECT_EQ(ReadAll(victim), "keep me");
  LineFile f(dir.path() / "ok.csv");
  EXPECT_THROW(f.Append("no newline"), Error);
}

TEST(CreateOutputFolderTest, CreatesNestedFoldersButNeverThroughALink) {
  testing::TempDir dir;
  CreateOutputFolder(dir.path() / "out", fs::path("rover") / "head" / "rgb");
  EXPECT_TRUE(fs::is_directory(dir.path() / "out" / "rover" / "head" / "rgb"));
  fs::create_directories(dir.path() / "elsewhere");
  fs::create_directory_symlink(dir.path() / "elsewhere", dir.path() / "out" / "cam");
  try {
    CreateOutputFolder(dir.path() / "out", fs::path("cam") / "rgb");
    FAIL() << "expected an Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("symbolic link"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(fs::is_empty(dir.path() / "elsewhere"));
  dir.Write("out/file", "x");
  EXPECT_THROW(CreateOutputFolder(dir.path() / "out", "file"), Error);
}

}  // namespace
}  // namespace penumbra
