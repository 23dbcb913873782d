#include "penumbra/slam/rgbd_sequence.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include "common/temp_dir.h"
#include "common/within_seconds.h"
#include "penumbra/core/error.h"
#include "penumbra/slam/rgbd_odometry.h"

namespace penumbra {
namespace {

using testing::TempDir;

TEST(RgbdSequence, ReadsAssociationsInOrder) {
  TempDir dir;
  dir.Write("associations.txt",
            "# comment\n0.000000 rgb/0.000000.png 0.000000 depth/0.000000.png\n"
            "0.100000 rgb/0.100000.png 0.100000 depth/0.100000.png\n");
  const std::vector<RgbdFrameFiles> f = ReadTumRgbdSequence(dir.path());
  ASSERT_EQ(f.size(), 2u);
  EXPECT_DOUBLE_EQ(f[1].time_sec, 0.1);
  EXPECT_EQ(f[1].rgb, dir.path() / "rgb/0.100000.png");
  EXPECT_EQ(f[1].depth, dir.path() / "depth/0.100000.png");
}

TEST(RgbdSequence, BadLinesNameFileAndLine) {
  TempDir dir;
  dir.Write("associations.txt", "0.0 rgb/a.png 0.0 depth/a.png\n0.0 rgb/b.png 0.0 depth/b.png\n");
  try {
    ReadTumRgbdSequence(dir.path());
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("associations.txt:2"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("does not increase"), std::string::npos) << e.what();
  }
  dir.Write("associations.txt", "0.0 rgb/a.png 0.0\n");
  EXPECT_THROW(ReadTumRgbdSequence(dir.path()), ConfigError);
  dir.Write("associations.txt", "# nothing\n");
  EXPECT_THROW(ReadTumRgbdSequence(dir.path()), ConfigError);
  EXPECT_THROW(ReadTumRgbdSequence(dir.path() / "missing"), ConfigError);
}

// a FIFO as associations.txt or camera_info.json blocked in open() for ever
TEST(RgbdSequence, AFifoAsTheListOrCameraInfoIsRefusedAtOnce) {
  TempDir dir;
  const std::string list = (dir.path() / "associations.txt").string();
  const std::string info = (dir.path() / "camera_info.json").string();
  ASSERT_EQ(mkfifo(list.c_str(), 0600), 0);
  ASSERT_EQ(mkfifo(info.c_str(), 0600), 0);
  const testing::WithinResult r = testing::RunWithin(10, [&] {
    int refused = 0;
    try {
      ReadTumRgbdSequence(dir.path());
    } catch (const ConfigError& e) {
      refused += e.problem().find("is not a regular file (a FIFO)") != std::string::npos;
    }
    try {
      ReadCameraInfoIntrinsics(info, "");
    } catch (const ConfigError& e) {
      refused += e.problem().find("is not a regular file (a FIFO)") != std::string::npos;
    }
    return refused == 2 ? 0 : 1;
  });
  EXPECT_TRUE(r.finished) << "a FIFO blocked the TUM RGB-D reader";
  EXPECT_EQ(r.exit_status, 0);
}

TEST(RgbdSequence, IntrinsicsFromCameraInfo) {
  TempDir dir;
  const std::string file = dir.Write(
      "camera_info.json",
      R"({"front": {"width": 160, "height": 120, "K": [100, 0, 80, 0, 101, 60, 0, 0, 1]}})");
  const PinholeIntrinsics k = ReadCameraInfoIntrinsics(file, "");
  EXPECT_EQ(k.fx, 100);
  EXPECT_EQ(k.fy, 101);
  EXPECT_EQ(k.cx, 80);
  EXPECT_EQ(k.cy, 60);
  EXPECT_THROW(ReadCameraInfoIntrinsics(file, "rear"), ConfigError);
  EXPECT_THROW(ReadCameraInfoIntrinsics(dir.Write("bad.json", "{"), ""), ConfigError);
}

TEST(RgbdOdometry, UnknownMethodsAndKinfuGapAreConfigErrors) {
  RgbdOdometryOptions o;
  o.intrinsics = {100, 100, 80, 60};
  const std::vector<RgbdFrameFiles> none;
  try {
    RunRgbdOdometry("opencv_kinfu", none, o);
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("OPENCV_ENABLE_NONFREE"), std::string::npos) << e.what();
  }
  EXPECT_THROW(RunRgbdOdometry("orb", none, o), ConfigError);
  o.intrinsics.fx = 0;
  EXPECT_THROW(RunRgbdOdometry("opencv_rgbd", none, o), ConfigError);
}

}  // namespace
}  // namespace penumbra
