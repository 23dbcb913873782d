// TUM trajectory files: the separators and comments TUM's tools accept, and clear errors
// (file:line, what was expected) for malformed files.
#include "penumbra/eval/trajectory.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include "common/temp_dir.h"
#include "common/within_seconds.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

TEST(TumTrajectory, ReadsSpacesTabsCommasCommentsAndBlankLines) {
  // comments (also indented), blank lines, CRLF, tabs, commas with spaces, '+' and exponents
  const std::string text =
      "# ground truth trajectory\n"
      "# timestamp tx ty tz qx qy qz qw\n"
      "\n"
      "1.5 1 2 3 0 0 0 1\n"
      "   # an indented comment\n"
      "1.6,4,5,6,0,0,0.7071067811865476,0.7071067811865476\r\n"
      "1.7\t+7\t8e0\t9.\t0 , 0 ,0 ,1   \n";
  const Trajectory t = ParseTumTrajectory(text, "gt.txt");
  ASSERT_EQ(t.size(), 3u);
  EXPECT_EQ(t.time_sec, (std::vector<double>{1.5, 1.6, 1.7}));
  EXPECT_EQ(t.X_WB[0].translation(), Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(t.X_WB[2].translation(), Eigen::Vector3d(7, 8, 9));
  EXPECT_TRUE(t.X_WB[0].linear().isIdentity(0));
  // qz = qw = 1/sqrt(2): 90 deg about z, scalar last
  EXPECT_LT((t.X_WB[1].linear() * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(),
            1e-15);
  EXPECT_EQ(t.Positions().col(1), Eigen::Vector3d(4, 5, 6));
}

TEST(TumTrajectory, NormalisesNearUnitQuaternions) {
  // 4-decimal quaternion (norm 0.99995): accepted and normalised
  const Trajectory t = ParseTumTrajectory("0 0 0 0 0 0 0.7071 0.7071\n", "f");
  EXPECT_NEAR(Eigen::Quaterniond(t.X_WB[0].linear()).norm(), 1.0, 1e-15);
  EXPECT_NEAR(t.X_WB[0].linear().determinant(), 1.0, 1e-14);
}

TEST(TumTrajectory, FormatReadsBackExactly) {
  Trajectory t;
  for (int k = 0; k < 5; ++k) {
    Pose X = Pose::Identity();
    X.linear() =
        Eigen::AngleAxisd(0.3 * k + 0.1, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    X.translation() = Eigen::Vector3d(0.1 * k, -1.0 / 3.0 * k, 1e-7 * k);
    t.time_sec.push_back(1e9 + 0.033333333 * k);  // a Unix-epoch timestamp
    t.X_WB.push_back(X);
  }
  const Trajectory back = ParseTumTrajectory(FormatTumTrajectory(t), "f");
  ASSERT_EQ(back.size(), t.size());
  for (size_t k = 0; k < t.size(); ++k) {
    EXPECT_EQ(back.time_sec[k], t.time_sec[k]);
    EXPECT_EQ(back.X_WB[k].translation(), t.X_WB[k].translation());
    EXPECT_LT((back.X_WB[k].linear() - t.X_WB[k].linear()).cwiseAbs().maxCoeff(), 1e-15);
  }
}

// the message of the ConfigError `text` raises
std::string ErrorOf(const std::string& text, int* line = nullptr) {
  try {
    ParseTumTrajectory(text, "est.txt");
  } catch (const ConfigError& e) {
    if (line) *line = e.line();
    return e.what();
  }
  return "(no error)";
}

TEST(TumTrajectory, MalformedLinesNameFileLineAndWhatWasExpected) {
  struct Case {
    std::string text;
    int line;
    std::string message;
  };
  const std::string ok = "# header\n0 0 0 0 0 0 0 1\n";
  const std::vector<Case> cases = {
      {ok + "1 0 0 0 0 0 1\n", 3,
       "est.txt:3: 7 fields; expected 8 numbers 'timestamp tx ty tz qx qy qz qw'"},
      {ok + "1 0 0 0 0 0 0 1 5\n", 3, "est.txt:3: 9 fields; expected 8 numbers"},
      {ok + "1\n", 3, "est.txt:3: 1 field; expected 8"},
      {ok + "1 0 abc 0 0 0 0 1\n", 3,
       "est.txt:3: field 3 (ty) 'abc' is not a finite decimal number; expected 8 numbers"},
      {ok + "1 0 0 0 0 0 0 nan\n", 3, "field 8 (qw) 'nan' is not a finite decimal number"},
      {ok + "1 inf 0 0 0 0 0 1\n", 3, "field 2 (tx) 'inf' is not a finite"},
      {ok + "1 0x10 0 0 0 0 0 1\n", 3, "field 2 (tx) '0x10'"},
      {ok + "1 1e999 0 0 0 0 0 1\n", 3, "field 2 (tx) '1e999'"},
      {ok + "1 +-1 0 0 0 0 0 1\n", 3, "field 2 (tx) '+-1'"},
      {ok + "1 0 0 0 0 0 0 1e\n", 3, "field 8 (qw) '1e'"},
      {ok + "1 0 0 0 0 0 0 0\n", 3,
       "est.txt:3: quaternion (qx qy qz qw) = (0 0 0 0) has norm 0; expected a unit quaternion"},
      {ok + "1 0 0 0 1 0 0 1\n", 3, "has norm 1.41421; expected a unit quaternion"},
      {ok + "0 0 0 0 0 0 0 1\n", 3,
       "est.txt:3: timestamp 0 is not after the previous pose's 0 (line 2); expected strictly "
       "increasing timestamps"},
      {ok + "\n# c\n-1 0 0 0 0 0 0 1\n", 5,
       "timestamp -1 is not after the previous pose's 0 (line 2)"},
      {"", 0, "est.txt: no poses (0 lines, all blank or comments); expected lines"},
      {"# only a comment\n\n", 0, "est.txt: no poses (2 lines"},
      {ok + "1 0 0 0 0 0 0 1 # trailing comment\n", 3, "est.txt:3: 11 fields"},
  };
  for (const Case& c : cases) {
    int line = -1;
    const std::string what = ErrorOf(c.text, &line);
    EXPECT_NE(what.find(c.message), std::string::npos) << "input:\n" << c.text << "\ngot: " << what;
    EXPECT_EQ(line, c.line) << c.text;
  }
}

TEST(TumTrajectory, FileErrorsNameThePath) {
  testing::TempDir tmp;
  const std::string missing = (tmp.path() / "missing.txt").string();
  try {
    ReadTumTrajectory(missing);
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.file(), missing);
    EXPECT_NE(std::string(e.what()).find("TUM trajectory file not found: " + missing),
              std::string::npos)
        << e.what();
  }
  try {
    ReadTumTrajectory(tmp.path());
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.problem(), "TUM trajectory file is a directory; expected a regular file");
  }
  // a FIFO is refused at once: open() without a writer blocked for ever
  const std::string fifo = (tmp.path() / "gt.txt").string();
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  const testing::WithinResult r = testing::RunWithin(10, [&] {
    try {
      ReadTumTrajectory(fifo);
    } catch (const ConfigError& e) {
      return e.problem() ==
                     "TUM trajectory file is not a regular file (a FIFO); expected a regular file"
                 ? 0
                 : 1;
    }
    return 2;
  });
  EXPECT_TRUE(r.finished) << "ReadTumTrajectory of a FIFO blocked";
  EXPECT_EQ(r.exit_status, 0);
  // binary garbage: an error, escaped in the message
  const std::string garbage =
      tmp.Write("g.bin", std::string("\x01\x02\xff\x00 1 2 3 4 5 6 7\n", 19));
  try {
    ReadTumTrajectory(garbage);
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.line(), 1);
    EXPECT_NE(std::string(e.what()).find("\\x01"), std::string::npos) << e.what();
  }
  const std::string good = tmp.Write("t.txt", "1 2 3 4 0 0 0 1\n2 2 3 4 0 0 0 1\n");
  EXPECT_EQ(ReadTumTrajectory(good).size(), 2u);
}

}  // namespace
}  // namespace penumbra
