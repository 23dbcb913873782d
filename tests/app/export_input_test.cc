// `penumbra export X.plog`: a run log named as the input is a regular file. a FIFO, a folder or
// a device named x.plog was reported as "no such run log"; each is refused naming what it is
// (exit 2) before a temporary folder is made, and a missing one is still "no such run log".

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <string>

#include "app/child_process.h"
#include "common/temp_dir.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

TEST(ExportInput, ARunLogThatIsNoRegularFileIsRefusedNamingWhatItIs) {
  testing::TempDir tmp;
  const std::string fifo = (tmp.path() / "f.plog").string();
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  const std::string dir = (tmp.path() / "d.plog").string();
  fs::create_directories(dir);
  struct Case {
    std::string input, format, out, message;
  };
  const std::string bag = (tmp.path() / "b.bag").string();
  const std::string ds = (tmp.path() / "ds").string();
  const std::vector<Case> cases = {
      {fifo, "tum", ds, fifo + ": run log is not a regular file (a FIFO); expected a regular file"},
      {fifo, "rosbag", bag,
       fifo + ": run log is not a regular file (a FIFO); expected a regular file"},
      {dir, "tum", ds, dir + ": run log is a directory; expected a regular file"},
      {(tmp.path() / "missing.plog").string(), "tum", ds, "no such run log"},
  };
  for (const Case& c : cases) {
    const testing::ProcessResult r =
        testing::RunPenumbra({"export", c.input, "--format", c.format, "--out", c.out}, tmp.path());
    EXPECT_EQ(r.exit_code, 2) << c.input << " " << c.format << ": " << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
  }
  // nothing was made beside --out
  for (const auto& e : fs::directory_iterator(tmp.path())) {
    const std::string name = e.path().filename().string();
    EXPECT_EQ(name.find("-tmp-"), std::string::npos) << name;
    EXPECT_NE(name, "ds");
    EXPECT_NE(name, "b.bag");
  }
}

}  // namespace
}  // namespace penumbra
