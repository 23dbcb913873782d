// a run log is a regular file: a folder or /dev/zero named as a run log was reported as an
// "empty file", and a FIFO blocked `replay` in open() for ever. each is refused at once naming
// the path and what it is.

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <string>

#include "common/temp_dir.h"
#include "common/within_seconds.h"
#include "penumbra/runlog/run_log_reader.h"

namespace penumbra {
namespace {

std::string RunLogOpenError(const std::string& path) {
  try {
    RunLogReader::Open(path, RunLogReadMode::kRecover);
  } catch (const RunLogError& e) {
    return e.what();
  }
  return "";
}

TEST(RunLogInputTest, AFolderIsRefusedAsADirectoryNotAsAnEmptyFile) {
  testing::TempDir tmp;
  EXPECT_EQ(
      RunLogOpenError(tmp.str()),
      tmp.str() + ": run log is a directory; expected a regular file (a penumbra run log, .plog)");
}

TEST(RunLogInputTest, DevZeroIsRefusedAsACharacterDevice) {
  EXPECT_EQ(RunLogOpenError("/dev/zero"),
            "/dev/zero: run log is not a regular file (a character device); expected a regular "
            "file (a penumbra run log, .plog)");
}

TEST(RunLogInputTest, AFifoIsRefusedAtOnceInsteadOfBlockingInOpen) {
  testing::TempDir tmp;
  const std::string fifo = (tmp.path() / "run.plog").string();
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  const std::string expected =
      fifo +
      ": run log is not a regular file (a FIFO); expected a regular file (a penumbra run "
      "log, .plog)";
  const testing::WithinResult r =
      testing::RunWithin(10, [&] { return RunLogOpenError(fifo) == expected ? 0 : 1; });
  EXPECT_TRUE(r.finished) << "RunLogReader::Open of a FIFO blocked";
  EXPECT_EQ(r.exit_status, 0);
  EXPECT_EQ(RunLogOpenError(fifo), expected);
}

}  // namespace
}  // namespace penumbra
