// tests of core/input_file.h: the whole file comes back byte for byte; a missing file, a
// folder, a device, a FIFO, a socket and a file above the cap are refused with a ConfigError
// naming the file and what it is (the size before anything is allocated: /dev/zero never ends
// and is refused at once; a FIFO without a writer blocked in open() for ever).

#include "penumbra/core/input_file.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "common/temp_dir.h"
#include "common/within_seconds.h"
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
  EXPECT_EQ(InputFileProblem(dir.str()), "world file is a directory; expected a regular file");
  EXPECT_EQ(InputFileProblem("/dev/zero"),
            "world file is not a regular file (a character device); expected a regular file");
}

TEST(InputFile, RefusesAFifoAtOnceInsteadOfWaitingForAWriter) {
  testing::TempDir dir;
  const std::string fifo = (dir.path() / "w.yaml").string();
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  // in a child with a deadline: open() of a FIFO without a writer blocked for ever
  const testing::WithinResult r = testing::RunWithin(10, [&] {
    try {
      ReadInputFile(fifo, "world file");
    } catch (const ConfigError& e) {
      return e.problem() == "world file is not a regular file (a FIFO); expected a regular file"
                 ? 0
                 : 1;
    }
    return 2;
  });
  EXPECT_TRUE(r.finished) << "ReadInputFile of a FIFO blocked";
  EXPECT_EQ(r.exit_status, 0);
  EXPECT_EQ(InputFileProblem(fifo),
            "world file is not a regular file (a FIFO); expected a regular file");
}

TEST(InputFile, RefusesASocketNamingIt) {
  testing::TempDir dir;
  const std::string path = (dir.path() / "s").string();
  const int fd = socket(AF_UNIX, SOCK_STREAM, 0);
  ASSERT_GE(fd, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  ASSERT_LT(path.size(), sizeof(addr.sun_path));
  path.copy(addr.sun_path, path.size());
  ASSERT_EQ(bind(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof(addr)), 0);
  EXPECT_EQ(InputFileProblem(path),
            "world file is not a regular file (a socket); expected a regular file");
  close(fd);
}

TEST(InputFile, FollowsALinkTheUserNamedAndRefusesOneWhenAskedTo) {
  testing::TempDir dir;
  const std::string target = dir.Write("real.yaml", "seed: 1\n");
  const std::filesystem::path link = dir.path() / "link.yaml";
  std::filesystem::create_symlink(target, link);
  EXPECT_EQ(ReadInputFile(link), "seed: 1\n");
  try {
    ReadInputFile(link, "world file", kMaxInputFileBytes, InputLinks::kRefuse);
    ADD_FAILURE() << "a link was followed";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.problem(),
              "world file is a symbolic link; expected a regular file (links are not followed "
              "here)");
  }
}

TEST(InputFile, OpenInputFileGivesABlockingDescriptorAndTheSize) {
  testing::TempDir dir;
  const std::string path = dir.Write("a.bin", "12345");
  const InputFile f = OpenInputFile(path, "run log");
  EXPECT_EQ(f.size, 5u);
  EXPECT_EQ(fcntl(f.fd.get(), F_GETFL) & O_NONBLOCK, 0);
  char buf[8];
  EXPECT_EQ(read(f.fd.get(), buf, sizeof(buf)), 5);
}

TEST(InputFile, RefusesAFileAboveTheCap) {
  testing::TempDir dir;
  const std::string path = dir.Write("big.yaml", std::string(101, 'a'));
  EXPECT_EQ(InputFileProblem(path, 100), "world file is 101 bytes; expected at most 100 bytes");
  EXPECT_EQ(ReadInputFile(path, "file", 101).size(), 101u);
}

}  // namespace
}  // namespace penumbra
