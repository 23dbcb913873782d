// the ground-truth images beyond rgb/depth/segmentation (range, normals, instance and semantic
// segmentation) written by CameraWriter, and so by the asynchronous writer, like the others.

#include <gtest/gtest.h>

#include <filesystem>

#include "common/temp_dir.h"
#include "penumbra/core/error.h"
#include "penumbra/output/async_frame_writer.h"
#include "penumbra/output/camera_writer.h"
#include "penumbra/output/png_io.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;
using testing::TempDir;

CameraOutputs ExtrasOnly() {
  CameraOutputs o = CameraOutputs::None();
  o[ImageKind::kRange] = o[ImageKind::kNormals] = o[ImageKind::kInstanceSegmentation] =
      o[ImageKind::kSemanticSegmentation] = true;
  return o;
}

CameraFrame ExtrasFrame(int64_t index) {
  CameraFrame f;
  f.camera = "cam";
  f.index = index;
  f.range_m = ImageF(3, 2, 1);
  f.range_m.data = {0.0f, 1.2344f, 1.2346f, 70.0f, 0.0004f, 2.0f};
  f.normal_O = ImageF(3, 2, 3, 0.0f);
  f.normal_O.data[0] = -1.0f;  // -> 0
  f.normal_O.data[1] = 1.0f;   // -> 255
  f.normal_O.data[2] = 2.0f;   // clamped -> 255
  f.body_id = ImageI32(3, 2, 1, -1);
  f.body_id.data[1] = 4;
  f.semantic_class = ImageI32(3, 2, 1, 0);
  f.semantic_class.data[5] = 7;
  return f;
}

TEST(CameraWriterExtras, RangeNormalsAndIdsAreWrittenAsPngs) {
  TempDir dir;
  CameraIntrinsics k = CameraIntrinsics::FromFovy(3, 2, 60);
  CameraWriter w(dir.path().string(), "cam", k, ExtrasOnly());
  for (const char* kind : {"range", "normals", "instance_segmentation", "semantic_segmentation"})
    EXPECT_TRUE(fs::is_directory(dir.path() / "cam" / kind)) << kind;
  EXPECT_FALSE(fs::exists(dir.path() / "cam" / "rgb"));
  w.Write(ExtrasFrame(0));
  const fs::path cam = dir.path() / "cam";
  const PngImage range = ReadPng((cam / "range" / "000000.png").string());
  EXPECT_EQ(range.bit_depth, 16);
  EXPECT_EQ(range.samples, (std::vector<uint16_t>{0, 1234, 1235, 65535, 1, 2000}));
  const PngImage normals = ReadPng((cam / "normals" / "000000.png").string());
  EXPECT_EQ(normals.channels, 3);
  EXPECT_EQ(normals.bit_depth, 8);
  EXPECT_EQ(normals.samples[0], 0);
  EXPECT_EQ(normals.samples[1], 255);
  EXPECT_EQ(normals.samples[2], 255);
  EXPECT_EQ(normals.samples[3], 128);  // 0 -> 127.5 rounds half away from zero
  const PngImage inst = ReadPng((cam / "instance_segmentation" / "000000.png").string());
  EXPECT_EQ(inst.samples, (std::vector<uint16_t>{0, 5, 0, 0, 0, 0}));
  const PngImage sem = ReadPng((cam / "semantic_segmentation" / "000000.png").string());
  EXPECT_EQ(sem.samples, (std::vector<uint16_t>{0, 0, 0, 0, 0, 7}));
}

TEST(CameraWriterExtras, AnIdThatDoesNotFitFailsTheWholeFrame) {
  TempDir dir;
  CameraWriter w(dir.path().string(), "cam", CameraIntrinsics::FromFovy(3, 2, 60), ExtrasOnly());
  CameraFrame f = ExtrasFrame(0);
  f.semantic_class.data[0] = 70000;
  try {
    w.Write(f);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "semantic class id 70000 does not fit a 16-bit PNG");
  }
  // all or nothing: the images written before the failing one are removed again
  for (const char* kind : {"range", "normals", "instance_segmentation", "semantic_segmentation"})
    EXPECT_FALSE(fs::exists(dir.path() / "cam" / kind / "000000.png")) << kind;
}

TEST(CameraWriterExtras, AMissingRequestedImageIsAnError) {
  TempDir dir;
  CameraWriter w(dir.path().string(), "cam", CameraIntrinsics::FromFovy(3, 2, 60), ExtrasOnly());
  CameraFrame f = ExtrasFrame(0);
  f.normal_O = ImageF();
  EXPECT_THROW(w.Write(f), Error);
}

TEST(CameraWriterExtras, TheAsynchronousWriterWritesThemToo) {
  TempDir dir;
  {
    AsyncFrameWriter w(dir.path().string());
    w.AddCamera("cam", CameraIntrinsics::FromFovy(3, 2, 60), ExtrasOnly());
    for (int64_t i = 0; i < 3; ++i) w.Submit(ExtrasFrame(i));
    w.Flush();
    EXPECT_EQ(w.FramesWritten().at("cam"), 3);
  }
  for (const char* kind : {"range", "normals", "instance_segmentation", "semantic_segmentation"})
    EXPECT_TRUE(fs::exists(dir.path() / "cam" / kind / "000002.png")) << kind;
}

}  // namespace
}  // namespace penumbra
