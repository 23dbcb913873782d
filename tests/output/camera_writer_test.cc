#include "penumbra/output/camera_writer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>

#include "common/temp_dir.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

using testing::ReadAll;
using testing::TempDir;

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) lines.push_back(line);
  return lines;
}

std::vector<std::string> Split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::string cur;
  std::istringstream in(s);
  while (std::getline(in, cur, sep)) out.push_back(cur);
  return out;
}

CameraFrame MakeFrame(const std::string& camera, int64_t index, int w, int h) {
  CameraFrame f;
  f.camera = camera;
  f.index = index;
  f.time_sec = 0.1 * static_cast<double>(index);
  f.X_WO = PoseFromXyzRpyDeg(Eigen::Vector3d(1.0 + index, -2.0, 0.25),
                             Eigen::Vector3d(-90, 0, -90 + 10.0 * index));
  f.rgb = ImageU8(w, h, 3);
  for (size_t i = 0; i < f.rgb.data.size(); ++i) f.rgb.data[i] = static_cast<uint8_t>(i + index);
  f.depth_m = ImageF(w, h, 1);
  for (size_t i = 0; i < f.depth_m.data.size(); ++i) f.depth_m.data[i] = 0.5f + 0.001f * i;
  f.geom_id = ImageI32(w, h, 1, -1);
  for (size_t i = 0; i < f.geom_id.data.size(); i += 3) f.geom_id.data[i] = static_cast<int32_t>(i);
  return f;
}

TEST(DepthToMillimetres, RoundsToNearestMillimetre) {
  ImageF d(8, 1, 1);
  d.data = {1.2344f, 1.2346f, 0.0f, 2.0f, 0.0004f, 65.534f, 70.0f, -1.0f};
  const ImageU16 mm = DepthToMillimetres(d);
  EXPECT_EQ(mm.width, 8);
  EXPECT_EQ(mm.channels, 1);
  EXPECT_EQ(mm.data[0], 1234);
  EXPECT_EQ(mm.data[1], 1235);
  EXPECT_EQ(mm.data[2], 0) << "no hit";
  EXPECT_EQ(mm.data[3], 2000);
  EXPECT_EQ(mm.data[4], 1) << "a hit closer than 0.5 mm must not read as no return";
  EXPECT_EQ(mm.data[5], 65534);
  EXPECT_EQ(mm.data[6], 65535) << "saturates";
  EXPECT_EQ(mm.data[7], 0) << "negative depth is no return";
}

TEST(DepthToMillimetres, NonFiniteIsNoReturn) {
  ImageF d(3, 1, 1);
  d.data = {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(),
            -std::numeric_limits<float>::infinity()};
  const ImageU16 mm = DepthToMillimetres(d);
  EXPECT_EQ(mm.data[0], 0);
  EXPECT_EQ(mm.data[1], 0);
  EXPECT_EQ(mm.data[2], 0);
}

TEST(SegmentationToU16, StoresIdPlusOne) {
  ImageI32 ids(5, 1, 1);
  ids.data = {-1, 0, 1, 41, 65534};
  const ImageU16 s = SegmentationToU16(ids);
  EXPECT_EQ(s.data[0], 0);
  EXPECT_EQ(s.data[1], 1);
  EXPECT_EQ(s.data[2], 2);
  EXPECT_EQ(s.data[3], 42);
  EXPECT_EQ(s.data[4], 65535);
}

TEST(SegmentationToU16, IdsThatDoNotFitThrow) {
  ImageI32 big(1, 1, 1, 65535);
  EXPECT_THROW(SegmentationToU16(big), Error);
  ImageI32 neg(1, 1, 1, -2);
  EXPECT_THROW(SegmentationToU16(neg), Error);
}

TEST(CameraFolder, NestsAtSlashesAndRejectsEscapes) {
  EXPECT_EQ(CameraFolder("front"), std::filesystem::path("front"));
  EXPECT_EQ(CameraFolder("rover/head"), std::filesystem::path("rover") / "head");
  for (const char* bad :
       {"", "/abs", "../up", "a/../b", "a/..", "./a", "a//b", "a/", "a\\b", "tab\there"}) {
    EXPECT_THROW(CameraFolder(bad), ConfigError) << "'" << bad << "'";
  }
  EXPECT_NO_THROW(CameraFolder("cam..1"));  // dots inside a name are fine
}

TEST(FrameFileName, ZeroPadsToSixDigits) {
  EXPECT_EQ(FrameFileName(0), "000000.png");
  EXPECT_EQ(FrameFileName(42), "000042.png");
  EXPECT_EQ(FrameFileName(1234567), "1234567.png");
}

TEST(FramesCsvRow, QuaternionHasNonNegativeW) {
  CameraFrame f;
  f.index = 3;
  f.time_sec = 0.3;
  // 200 deg about z: Eigen's matrix-to-quaternion gives qw < 0 here; the row must not
  f.X_WO = Pose::Identity();
  f.X_WO.linear() =
      Eigen::AngleAxisd(200.0 * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  ASSERT_LT(Eigen::Quaterniond(f.X_WO.linear()).w(), 0.0) << "test premise";
  f.X_WO.translation() = Eigen::Vector3d(0.1, -2.5, 1e-3);
  const std::string row = FramesCsvRow(f);
  const auto cols = Split(row.substr(0, row.size() - 1), ',');
  ASSERT_EQ(cols.size(), 9u);
  EXPECT_EQ(cols[0], "3");
  EXPECT_EQ(cols[1], "0.3");
  EXPECT_EQ(std::stod(cols[2]), 0.1);
  EXPECT_EQ(std::stod(cols[3]), -2.5);
  EXPECT_EQ(std::stod(cols[4]), 1e-3);
  const double qw = std::stod(cols[5]), qx = std::stod(cols[6]), qy = std::stod(cols[7]),
               qz = std::stod(cols[8]);
  EXPECT_GE(qw, 0.0);
  EXPECT_NEAR(qw * qw + qx * qx + qy * qy + qz * qz, 1.0, 1e-12);
  // 200 deg about +z == -160 deg about +z: q = (cos 80 deg, 0, 0, -sin 80 deg)
  EXPECT_NEAR(qw, std::cos(80.0 * M_PI / 180.0), 1e-12);
  EXPECT_NEAR(qz, -std::sin(80.0 * M_PI / 180.0), 1e-12);
  EXPECT_NEAR(qx, 0.0, 1e-12);
  EXPECT_NEAR(qy, 0.0, 1e-12);
}

TEST(FramesCsvRow, ReadsBackToTheSameDoubles) {
  CameraFrame f;
  f.index = 7;
  f.time_sec = 1.0 / 3.0;
  f.X_WO = PoseFromXyzRpyDeg(Eigen::Vector3d(M_PI, -M_E, 1.0 / 7.0), Eigen::Vector3d(12, -34, 56));
  const std::string row = FramesCsvRow(f);
  ASSERT_EQ(row.back(), '\n');
  const auto cols = Split(row.substr(0, row.size() - 1), ',');
  ASSERT_EQ(cols.size(), 9u);
  EXPECT_EQ(std::stod(cols[1]), 1.0 / 3.0);
  EXPECT_EQ(std::stod(cols[2]), M_PI);
  EXPECT_EQ(std::stod(cols[3]), -M_E);
  EXPECT_EQ(std::stod(cols[4]), 1.0 / 7.0);
  Eigen::Quaterniond q(std::stod(cols[5]), std::stod(cols[6]), std::stod(cols[7]),
                       std::stod(cols[8]));
  EXPECT_TRUE(q.toRotationMatrix().isApprox(f.X_WO.linear(), 1e-14));
}

TEST(FramesCsvRow, HalfTurnPicksAPositiveFirstComponent) {
  CameraFrame f;
  // exactly a half turn about y, so qw is exactly 0 and q, -q tie on the qw rule
  f.X_WO.linear() = Eigen::Vector3d(-1, 1, -1).asDiagonal();
  const auto cols = Split(FramesCsvRow(f).substr(0, FramesCsvRow(f).size() - 1), ',');
  EXPECT_NEAR(std::stod(cols[5]), 0.0, 1e-12);
  EXPECT_NEAR(std::stod(cols[7]), 1.0, 1e-12);  // qy, sign made positive
}

TEST(CameraWriter, WritesImagesPosesAndIntrinsics) {
  TempDir dir;
  const CameraIntrinsics intr = CameraIntrinsics::FromFovy(8, 6, 70.0);
  CameraOutputs outs;
  outs[ImageKind::kRgb] = outs[ImageKind::kDepth] = outs[ImageKind::kSegmentation] = true;
  CameraWriter w(dir.str(), "rover/head", intr, outs);
  const auto folder = dir.path() / "rover" / "head";
  EXPECT_EQ(w.folder(), folder);

  std::vector<CameraFrame> frames;
  for (int i = 0; i < 3; ++i) {
    frames.push_back(MakeFrame("rover/head", i, 8, 6));
    w.Write(frames.back());
  }
  EXPECT_EQ(w.frames_written(), 3);

  // images
  for (int i = 0; i < 3; ++i) {
    const PngImage rgb = ReadPng((folder / "rgb" / FrameFileName(i)).string());
    EXPECT_EQ(rgb.bit_depth, 8);
    EXPECT_EQ(rgb.channels, 3);
    EXPECT_TRUE(
        std::equal(frames[i].rgb.data.begin(), frames[i].rgb.data.end(), rgb.samples.begin()));
    const PngImage depth = ReadPng((folder / "depth" / FrameFileName(i)).string());
    EXPECT_EQ(depth.bit_depth, 16);
    EXPECT_EQ(depth.channels, 1);
    const ImageU16 mm = DepthToMillimetres(frames[i].depth_m);
    EXPECT_TRUE(std::equal(mm.data.begin(), mm.data.end(), depth.samples.begin()));
    EXPECT_EQ(depth.samples[0], 500);
    const PngImage seg = ReadPng((folder / "segmentation" / FrameFileName(i)).string());
    EXPECT_EQ(seg.bit_depth, 16);
    for (size_t k = 0; k < seg.samples.size(); ++k) {
      ASSERT_EQ(seg.samples[k], frames[i].geom_id.data[k] + 1) << "pixel " << k;
    }
  }

  // frames.csv
  const auto lines = Lines(ReadAll(folder / "frames.csv"));
  ASSERT_EQ(lines.size(), 4u);
  EXPECT_EQ(lines[0], "frame,time_sec,x,y,z,qw,qx,qy,qz");
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(lines[i + 1] + "\n", FramesCsvRow(frames[i]));
    const auto cols = Split(lines[i + 1], ',');
    EXPECT_EQ(std::stoll(cols[0]), i);
    EXPECT_EQ(std::stod(cols[2]), 1.0 + i);
    EXPECT_GE(std::stod(cols[5]), 0.0);
  }

  // intrinsics.json
  const auto j = nlohmann::json::parse(ReadAll(folder / "intrinsics.json"));
  EXPECT_EQ(j.at("width"), 8);
  EXPECT_EQ(j.at("height"), 6);
  EXPECT_DOUBLE_EQ(j.at("fx").get<double>(), intr.fx);
  EXPECT_DOUBLE_EQ(j.at("fy").get<double>(), intr.fy);
  EXPECT_DOUBLE_EQ(j.at("cx").get<double>(), intr.cx);
  EXPECT_DOUBLE_EQ(j.at("cy").get<double>(), intr.cy);
  EXPECT_EQ(j.at("model"), "pinhole");
  EXPECT_EQ(j.at("optical_frame"), "opencv (x right, y down, z forward)");
  EXPECT_EQ(j.at("camera"), "rover/head");
}

TEST(CameraWriter, OnlyRequestedOutputsAreWritten) {
  TempDir dir;
  CameraOutputs outs;
  outs[ImageKind::kRgb] = true;
  outs[ImageKind::kDepth] = false;
  outs[ImageKind::kSegmentation] = false;
  CameraWriter w(dir.str(), "front", CameraIntrinsics::FromFovy(4, 3, 60), outs);
  CameraFrame f = MakeFrame("front", 0, 4, 3);
  f.depth_m = ImageF();  // not requested, may be empty
  w.Write(f);
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "front" / "rgb" / "000000.png"));
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "front" / "depth"));
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "front" / "segmentation"));
}

TEST(CameraWriter, RejectsMismatchedFrames) {
  TempDir dir;
  CameraOutputs outs;
  outs[ImageKind::kDepth] = true;
  CameraWriter w(dir.str(), "front", CameraIntrinsics::FromFovy(4, 3, 60), outs);
  EXPECT_THROW(w.Write(MakeFrame("other", 0, 4, 3)), Error);  // wrong camera
  EXPECT_THROW(w.Write(MakeFrame("front", 0, 5, 3)), Error);  // wrong size
  CameraFrame no_depth = MakeFrame("front", 0, 4, 3);
  no_depth.depth_m = ImageF();
  EXPECT_THROW(w.Write(no_depth), Error);  // requested output missing
  w.Write(MakeFrame("front", 1, 4, 3));
  EXPECT_THROW(w.AppendPose(MakeFrame("front", 1, 4, 3)), Error);  // index not increasing
  EXPECT_EQ(w.frames_written(), 1);
}

TEST(CameraWriter, BadNamesAreConfigErrors) {
  TempDir dir;
  EXPECT_THROW(CameraWriter(dir.str(), "../escape", CameraIntrinsics::FromFovy(4, 3, 60), {}),
               ConfigError);
  EXPECT_THROW(CameraWriter(dir.str(), "/etc/cam", CameraIntrinsics::FromFovy(4, 3, 60), {}),
               ConfigError);
  EXPECT_FALSE(std::filesystem::exists(dir.path().parent_path() / "escape"));
}

TEST(CameraWriter, SegmentationIdTooLargeIsAnError) {
  TempDir dir;
  CameraOutputs outs;
  outs[ImageKind::kRgb] = false;
  outs[ImageKind::kSegmentation] = true;
  CameraWriter w(dir.str(), "seg", CameraIntrinsics::FromFovy(4, 3, 60), outs);
  CameraFrame f = MakeFrame("seg", 0, 4, 3);
  f.geom_id.data[5] = 70000;
  EXPECT_THROW(w.WriteImages(f), Error);
}

}  // namespace
}  // namespace penumbra
