#include "penumbra/output/async_frame_writer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <mutex>
#include <sstream>
#include <thread>
#include <vector>

#include "common/temp_dir.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

using testing::ReadAll;
using testing::TempDir;

CameraFrame Frame(const std::string& camera, int64_t index, int w, int h) {
  CameraFrame f;
  f.camera = camera;
  f.index = index;
  f.time_sec = 0.05 * static_cast<double>(index);
  f.X_WO.translation() = Eigen::Vector3d(0.01 * index, 0, 1);
  f.rgb = ImageU8(w, h, 3, static_cast<uint8_t>(index));
  // make later frames cheaper to encode than earlier ones, so that with two threads
  // they tend to finish out of order
  if (index % 2 == 0) {
    for (size_t i = 0; i < f.rgb.data.size(); ++i) f.rgb.data[i] = static_cast<uint8_t>(i * 7919);
  }
  f.depth_m = ImageF(w, h, 1, 1.0f + 0.001f * static_cast<float>(index));
  f.geom_id = ImageI32(w, h, 1, static_cast<int32_t>(index));
  return f;
}

std::vector<std::string> CsvLines(const std::filesystem::path& p) {
  std::vector<std::string> lines;
  std::istringstream in(ReadAll(p));
  std::string line;
  while (std::getline(in, line)) lines.push_back(line);
  return lines;
}

CameraOutputs AllOutputs() {
  CameraOutputs o;
  o[ImageKind::kRgb] = o[ImageKind::kDepth] = o[ImageKind::kSegmentation] = true;
  return o;
}

TEST(AsyncFrameWriter, WritesEveryFrameAndRowsInOrder) {
  TempDir dir;
  AsyncFrameWriterOptions opt;
  opt.num_threads = 2;
  opt.queue_capacity = 3;
  const int kFrames = 24;
  {
    AsyncFrameWriter writer(dir.str(), opt);
    writer.AddCamera("front", CameraIntrinsics::FromFovy(64, 48, 70), AllOutputs());
    writer.AddCamera("rover/head", CameraIntrinsics::FromFovy(32, 24, 70), AllOutputs());
    for (int i = 0; i < kFrames; ++i) {
      writer.Submit(Frame("front", i, 64, 48));
      writer.Submit(Frame("rover/head", 2 * i, 32, 24));  // gaps in indices are allowed
    }
    writer.Flush();
    const auto written = writer.FramesWritten();
    EXPECT_EQ(written.at("front"), kFrames);
    EXPECT_EQ(written.at("rover/head"), kFrames);
  }
  for (const auto& [camera, step] : {std::pair<std::string, int>{"front", 1}, {"rover/head", 2}}) {
    const auto folder = dir.path() / CameraFolder(camera);
    const auto lines = CsvLines(folder / "frames.csv");
    ASSERT_EQ(lines.size(), static_cast<size_t>(kFrames + 1)) << camera;
    for (int i = 0; i < kFrames; ++i) {
      const int64_t index = static_cast<int64_t>(i) * step;
      EXPECT_EQ(lines[i + 1] + "\n", FramesCsvRow(Frame(camera, index, 1, 1))) << camera;
      const PngImage seg = ReadPng((folder / "segmentation" / FrameFileName(index)).string());
      EXPECT_EQ(seg.samples[0], index + 1);
      EXPECT_TRUE(std::filesystem::exists(folder / "rgb" / FrameFileName(index)));
      const PngImage depth = ReadPng((folder / "depth" / FrameFileName(index)).string());
      EXPECT_EQ(depth.samples[0], 1000 + index);
    }
  }
}

TEST(AsyncFrameWriter, DestructorDrainsTheQueue) {
  TempDir dir;
  AsyncFrameWriterOptions opt;
  opt.num_threads = 1;
  opt.queue_capacity = 8;
  {
    AsyncFrameWriter writer(dir.str(), opt);
    writer.AddCamera("cam", CameraIntrinsics::FromFovy(16, 12, 60), AllOutputs());
    for (int i = 0; i < 6; ++i) writer.Submit(Frame("cam", i, 16, 12));
  }  // no Flush
  EXPECT_EQ(CsvLines(dir.path() / "cam" / "frames.csv").size(), 7u);
  for (int i = 0; i < 6; ++i) {
    EXPECT_TRUE(std::filesystem::exists(dir.path() / "cam" / "rgb" / FrameFileName(i)));
  }
}

TEST(AsyncFrameWriter, WriteErrorIsRethrownAndEarlierFramesKept) {
  TempDir dir;
  AsyncFrameWriterOptions opt;
  opt.num_threads = 2;
  AsyncFrameWriter writer(dir.str(), opt);
  writer.AddCamera("cam", CameraIntrinsics::FromFovy(16, 12, 60), AllOutputs());
  for (int i = 0; i < 3; ++i) writer.Submit(Frame("cam", i, 16, 12));
  writer.Flush();

  // make the depth folder unwritable for anyone (root included): a file where the folder was
  const auto depth_dir = dir.path() / "cam" / "depth";
  std::filesystem::remove_all(depth_dir);
  std::ofstream(depth_dir) << "not a folder";

  writer.Submit(Frame("cam", 3, 16, 12));
  try {
    writer.Flush();
    FAIL() << "expected the write error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("depth"), std::string::npos) << e.what();
  }
  // reported once; the writer keeps working
  EXPECT_NO_THROW(writer.Flush());

  std::filesystem::remove(depth_dir);
  std::filesystem::create_directories(depth_dir);
  writer.Submit(Frame("cam", 4, 16, 12));
  writer.Flush();

  const auto lines = CsvLines(dir.path() / "cam" / "frames.csv");
  ASSERT_EQ(lines.size(), 5u);  // header + frames 0, 1, 2, 4 (3 failed, no row)
  EXPECT_EQ(lines[1].substr(0, 2), "0,");
  EXPECT_EQ(lines[3].substr(0, 2), "2,");
  EXPECT_EQ(lines[4].substr(0, 2), "4,");
  for (int i : {0, 1, 2}) {
    EXPECT_TRUE(std::filesystem::exists(dir.path() / "cam" / "rgb" / FrameFileName(i)));
  }
  EXPECT_EQ(writer.FramesWritten().at("cam"), 4);
}

TEST(AsyncFrameWriter, ErrorSurfacesOnNextSubmit) {
  TempDir dir;
  AsyncFrameWriterOptions opt;
  opt.num_threads = 1;
  opt.queue_capacity = 1;
  AsyncFrameWriter writer(dir.str(), opt);
  writer.AddCamera("cam", CameraIntrinsics::FromFovy(8, 6, 60), AllOutputs());
  CameraFrame bad = Frame("cam", 0, 8, 6);
  bad.geom_id.data[0] = 1 << 20;  // does not fit 16 bits
  writer.Submit(std::move(bad));
  // capacity 1: this Submit waits for the bad frame to finish, then reports its error
  EXPECT_THROW(writer.Submit(Frame("cam", 1, 8, 6)), Error);
  writer.Submit(Frame("cam", 2, 8, 6));
  writer.Flush();
  EXPECT_EQ(writer.FramesWritten().at("cam"), 1);
}

TEST(AsyncFrameWriter, RejectsUnknownCamerasAndOutOfOrderFrames) {
  TempDir dir;
  AsyncFrameWriter writer(dir.str());
  writer.AddCamera("cam", CameraIntrinsics::FromFovy(8, 6, 60), AllOutputs());
  EXPECT_THROW(writer.AddCamera("cam", CameraIntrinsics::FromFovy(8, 6, 60), AllOutputs()), Error);
  EXPECT_THROW(writer.Submit(Frame("nope", 0, 8, 6)), Error);
  writer.Submit(Frame("cam", 5, 8, 6));
  EXPECT_THROW(writer.Submit(Frame("cam", 5, 8, 6)), Error);
  EXPECT_THROW(writer.Submit(Frame("cam", 4, 8, 6)), Error);
  writer.Flush();
  EXPECT_EQ(writer.FramesWritten().at("cam"), 1);
}

TEST(AsyncFrameWriter, BadOptionsAreConfigErrors) {
  TempDir dir;
  AsyncFrameWriterOptions opt;
  opt.queue_capacity = 0;
  EXPECT_THROW(AsyncFrameWriter(dir.str(), opt), ConfigError);
  opt.queue_capacity = 8;
  opt.num_threads = -1;
  EXPECT_THROW(AsyncFrameWriter(dir.str(), opt), ConfigError);
  opt.num_threads = 9;
  EXPECT_THROW(AsyncFrameWriter(dir.str(), opt), ConfigError);
}

// 0 threads: half the machine's cores, at least 2 and at most 8; a count given is kept
TEST(AsyncFrameWriter, ZeroThreadsIsHalfTheCoresFromTwoToEight) {
  AsyncFrameWriterOptions opt;
  opt.num_threads = 0;
  const int cores = static_cast<int>(std::thread::hardware_concurrency());
  EXPECT_EQ(opt.ResolvedThreads(), std::clamp(cores / 2, 2, 8));
  EXPECT_GE(opt.ResolvedThreads(), 2);
  EXPECT_LE(opt.ResolvedThreads(), 8);
  opt.num_threads = 3;
  EXPECT_EQ(opt.ResolvedThreads(), 3);
  TempDir dir;
  opt.num_threads = 0;
  AsyncFrameWriter writer(dir.str(), opt);
  writer.AddCamera("cam", CameraIntrinsics::FromFovy(32, 24, 70), AllOutputs());
  for (int i = 0; i < 4; ++i) writer.Submit(Frame("cam", i, 32, 24));
  writer.Flush();
  EXPECT_EQ(CsvLines(dir.path() / "cam" / "frames.csv").size(), 5u);
}

TEST(AsyncFrameWriter, HandsEachWrittenFrameBackWithItsImages) {
  TempDir dir;
  AsyncFrameWriterOptions opt;
  opt.num_threads = 2;
  std::mutex mu;
  std::vector<CameraFrame> back;
  opt.on_written = [&](CameraFrame&& f) {
    std::lock_guard<std::mutex> lock(mu);
    back.push_back(std::move(f));
  };
  const int kFrames = 6;
  {
    AsyncFrameWriter writer(dir.str(), opt);
    writer.AddCamera("front", CameraIntrinsics::FromFovy(64, 48, 70), AllOutputs());
    for (int i = 0; i < kFrames; ++i) writer.Submit(Frame("front", i, 64, 48));
    writer.Flush();
    // the rows are written from what the writer kept, not from the images it gave back
    EXPECT_EQ(CsvLines(dir.path() / "front" / "frames.csv").size(), 1u + kFrames);
  }
  ASSERT_EQ(back.size(), static_cast<size_t>(kFrames));
  std::vector<int> seen;
  for (const CameraFrame& f : back) {
    EXPECT_EQ(f.camera, "front");
    ASSERT_EQ(f.rgb.width, 64);
    ASSERT_EQ(f.rgb.data.size(), 64u * 48 * 3);
    ASSERT_EQ(f.depth_m.data.size(), 64u * 48);
    ASSERT_EQ(f.geom_id.data.size(), 64u * 48);
    // the pixels are the submitted frame's (Frame: geom id = index)
    const int index = f.geom_id.data[0];
    seen.push_back(index);
    EXPECT_EQ(f.rgb.data, Frame("front", index, 64, 48).rgb.data);
    EXPECT_FLOAT_EQ(f.depth_m.data[5], 1.0f + 0.001f * static_cast<float>(index));
  }
  std::sort(seen.begin(), seen.end());
  for (int i = 0; i < kFrames; ++i) EXPECT_EQ(seen[i], i);
}

}  // namespace
}  // namespace penumbra
