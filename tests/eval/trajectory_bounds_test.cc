// a TUM file is regular text of bounded size: /dev/zero (not a regular file), a file of
// NULs and an endless line are refused at once with the file and line, and so are coordinates no
// robot reaches (1e308 printed NaN metrics and exit 0) and timestamps beyond the year 2286.

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "common/temp_dir.h"
#include "penumbra/core/error.h"
#include "penumbra/eval/trajectory.h"

namespace penumbra {
namespace {

// the ConfigError of reading `path` (its line in *line), or "" when it reads
std::string TumBoundsReadError(const std::string& path, int* line) {
  try {
    ReadTumTrajectory(path);
  } catch (const ConfigError& e) {
    *line = e.line();
    return e.what();
  }
  return "";
}

std::string TumBoundsParseError(const std::string& text, int* line) {
  try {
    ParseTumTrajectory(text, "est.txt");
  } catch (const ConfigError& e) {
    *line = e.line();
    return e.what();
  }
  return "";
}

TEST(TumTrajectoryBounds, DevZeroAndNulsAreRefusedAtTheirLine) {
  int line = -1;
  // /dev/zero never ends: refused before a byte is read, as the device it is
  std::string err = TumBoundsReadError("/dev/zero", &line);
  EXPECT_EQ(line, 0);
  EXPECT_NE(err.find("/dev/zero: TUM trajectory file is not a regular file (a character "
                     "device); expected a regular file"),
            std::string::npos)
      << err;

  testing::TempDir tmp;
  const std::string ok = "1 0 0 0 0 0 0 1\n2 0 0 0 0 0 0 1\n";
  const std::string nuls = tmp.Write("nuls.txt", ok + std::string(1 << 20, '\0'));
  line = -1;
  err = TumBoundsReadError(nuls, &line);
  EXPECT_EQ(line, 3) << err;
  EXPECT_NE(err.find(nuls + ":3: column 1 holds the byte 0x00"), std::string::npos) << err;
  EXPECT_NE(err.find("binary data; expected a TUM text file"), std::string::npos) << err;
  // a NUL inside a pose line, through the text parser as well
  line = -1;
  err = TumBoundsParseError(ok + std::string("3 0 0 0\0 0 0 0 1\n", 17), &line);
  EXPECT_EQ(line, 3);
  EXPECT_NE(err.find("column 8 holds the byte 0x00"), std::string::npos) << err;
}

TEST(TumTrajectoryBounds, AnOverlongLineIsRefusedWithFileAndLine) {
  testing::TempDir tmp;
  // 1 MiB of digits on line 2: refused as a long line, not read as one huge number
  const std::string path =
      tmp.Write("long.txt", "1 0 0 0 0 0 0 1\n" + std::string(1 << 20, '7') + "\n");
  int line = -1;
  const std::string err = TumBoundsReadError(path, &line);
  EXPECT_EQ(line, 2);
  EXPECT_NE(err.find(path + ":2: line of more than 4096 bytes ('7777"), std::string::npos) << err;
  // a line of exactly the limit is fine (a comment)
  EXPECT_EQ(
      ParseTumTrajectory("#" + std::string(kTumMaxLineBytes - 1, 'x') + "\n1 0 0 0 0 0 0 1\n", "f")
          .size(),
      1u);
}

TEST(TumTrajectoryBounds, AbsurdCoordinatesAndTimestampsAreRefusedWithTheLine) {
  const std::string ok = "1 0 0 0 0 0 0 1\n";
  struct Case {
    std::string line;
    std::string message;
  };
  const Case cases[] = {
      {"2 1e308 0 0 0 0 0 1", "est.txt:2: field 2 (tx) 1e+308 is beyond +-1e+06 m"},
      {"2 0 -2000000 0 0 0 0 1", "est.txt:2: field 3 (ty) -2000000 is beyond +-1e+06 m"},
      {"2 0 0 1.5e6 0 0 0 1", "est.txt:2: field 4 (tz) 1500000 is beyond +-1e+06 m"},
      {"1e300 0 0 0 0 0 0 1", "est.txt:2: timestamp 1e+300 is beyond +-1e+10 s"},
      {"2 nan 0 0 0 0 0 1", "est.txt:2: field 2 (tx) 'nan' is not a finite decimal number"},
      {"2 inf 0 0 0 0 0 1", "est.txt:2: field 2 (tx) 'inf' is not a finite decimal number"},
  };
  for (const Case& c : cases) {
    int line = -1;
    const std::string err = TumBoundsParseError(ok + c.line + "\n", &line);
    EXPECT_EQ(line, 2) << c.line;
    EXPECT_NE(err.find(c.message), std::string::npos) << c.line << "\ngot: " << err;
  }
  // the largest values accepted
  EXPECT_EQ(ParseTumTrajectory("1e10 1e6 -1e6 1e6 0 0 0 1\n", "f").size(), 1u);
}

}  // namespace
}  // namespace penumbra
