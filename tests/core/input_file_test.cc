// tests of core/input_file.h: the whole file comes back byte for byte; a missing file, a
// folder, a device and a file above the cap are refused with a ConfigError naming the file
// (the size before anything is allocated: /dev/zero never ends and is refused at once).

#include "penumbra/core/input_file.h"

#include <gtest/gtest.h>

#include <string>

#include "common/temp_dir.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

// the problem text of the ConfigError ReadInputFile throws for `path`
std::string InputFileProblem(const std::string& path, size_t max_bytes = kMaxInputFileBytes) {
  try {
    ReadInputFile(path, "world file", max_bytes);
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.file(), path);
    return e.problem();
  }
  ADD_FAILURE() << "no ConfigError for " << path;
  return "";
}

TEST(InputFile, ReadsTheWholeFile) {
  testing::TempDir dir;
  std::string bytes = "seed: 3\n";
  bytes += std::string(1, '\0') + std::string(200000, 'x');  // binary and above one read
  const std::string path = dir.Write("w.yaml", bytes);
  EXPECT_EQ(ReadInputFile(path), bytes);
  EXPECT_EQ(ReadInputFile(dir.Write("empty.yaml", "")), "");
}

TEST(InputFile, RefusesMissingFilesFoldersAndDevices) {
  testing::TempDir dir;
  const std::string missing = (dir.path() / "nope.yaml").string();
  const std::string p = InputFileProblem(missing);
  EXPECT_NE(p.find("world file not found: " + missing), std::string::npos) << p;
  EXPECT_NE(InputFileProblem(dir.str()).find("not a regular file"), std::string::npos);
  EXPECT_NE(InputFileProblem("/dev/zero").find("not a regular file"), std::string::npos);
}

TEST(InputFile, RefusesAFileAboveTheCap) {
  testing::TempDir dir;
  const std::string path = dir.Write("big.yaml", std::string(101, 'a'));
  EXPECT_EQ(InputFileProblem(path, 100), "world file is 101 bytes; expected at most 100 bytes");
  EXPECT_EQ(ReadInputFile(path, "file", 101).size(), 101u);
}

}  // namespace
}  // namespace penumbra
