// CheckImageFileSize reads an image's header through core/input_file.h: a FIFO named as an
// image blocked in open() for ever; a FIFO, a folder and a device are refused naming what they
// are, a missing file is left to the decoder.

#include "penumbra/core/image_file_limits.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <string>

#include "common/temp_dir.h"
#include "common/within_seconds.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

std::string ImageFileProblem(const std::string& path) {
  try {
    CheckImageFileSize(path);
  } catch (const ConfigError& e) {
    return e.problem();
  }
  return "";
}

TEST(ImageFileLimits, AFifoAFolderAndADeviceAreRefusedAtOnce) {
  testing::TempDir dir;
  const std::string fifo = (dir.path() / "000001.png").string();
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  const std::string expected = "image file is not a regular file (a FIFO); expected a regular file";
  const testing::WithinResult r =
      testing::RunWithin(10, [&] { return ImageFileProblem(fifo) == expected ? 0 : 1; });
  EXPECT_TRUE(r.finished) << "CheckImageFileSize of a FIFO blocked";
  EXPECT_EQ(r.exit_status, 0);
  EXPECT_EQ(ImageFileProblem(fifo), expected);
  EXPECT_EQ(ImageFileProblem(dir.str()), "image file is a directory; expected a regular file");
  EXPECT_EQ(ImageFileProblem("/dev/zero"),
            "image file is not a regular file (a character device); expected a regular file");
  EXPECT_EQ(ImageFileProblem((dir.path() / "missing.png").string()), "");
}

}  // namespace
}  // namespace penumbra
