// a world file may come from anyone: its `record.file` names a new run log inside the output
// folder, so an absolute path, a ".." component or an empty / "." component is refused with the
// world file's line (a shared world overwrote a user's .plog outside the folder).

#include <gtest/gtest.h>

#include <string>

#include "penumbra/core/error.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

std::string RecordError(const std::string& file) {
  try {
    ParseWorld("duration_sec: 1\nrecord:\n  file: '" + file + "'\n", "w.yaml");
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.file(), "w.yaml");
    EXPECT_EQ(e.line(), 3) << e.what();
    EXPECT_EQ(e.key(), "record.file") << e.what();
    return e.what();
  }
  return "";
}

TEST(RecordFilePathTest, ARecordFileOutsideTheOutputFolderIsRefusedWithItsLine) {
  EXPECT_NE(RecordError("/home/user/old.plog").find("is absolute"), std::string::npos);
  EXPECT_NE(RecordError("../old.plog").find("'..' component"), std::string::npos);
  EXPECT_NE(RecordError("logs/../../old.plog").find("'..' component"), std::string::npos);
  EXPECT_NE(RecordError("logs//run.plog").find("empty component"), std::string::npos);
  EXPECT_NE(RecordError("./run.plog").find("'.' component"), std::string::npos);
  EXPECT_NE(RecordError("run.log").find("does not end in .plog"), std::string::npos);
  // inside the output folder: accepted (a folder on the way must exist when the run starts)
  EXPECT_EQ(ParseWorld("record: {file: run.plog}\n", "w.yaml").record.file, "run.plog");
  EXPECT_EQ(ParseWorld("record: {file: logs/run.plog}\n", "w.yaml").record.file, "logs/run.plog");
}

}  // namespace
}  // namespace penumbra
