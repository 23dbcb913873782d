// the PNG writer's time accounting behind run.json's "png_encode_sec" and "png_write_sec"
// (docs/gpu.md, "Where a run's time goes"): WritePngRgb8 / WritePngGray16 add their encoding
// and file writing to a PngWriteTimes, and AsyncFrameWriter sums them over its cameras.

#include <gtest/gtest.h>

#include "common/temp_dir.h"
#include "penumbra/output/async_frame_writer.h"
#include "penumbra/output/png_io.h"

namespace penumbra {
namespace {

using testing::TempDir;

TEST(PngWriteTimes, EachWriteAddsItsEncodingAndItsFileWrite) {
  TempDir dir;
  ImageU8 rgb(64, 48, 3);
  for (size_t i = 0; i < rgb.data.size(); ++i) rgb.data[i] = static_cast<uint8_t>(i * 31);
  const ImageU16 grey(64, 48, 1, 1234);
  PngWriteTimes t;
  WritePngRgb8((dir.path() / "a.png").string(), rgb, {}, &t);
  EXPECT_GT(t.encode_sec, 0);
  EXPECT_GT(t.write_sec, 0);
  const PngWriteTimes after_one = t;
  WritePngGray16((dir.path() / "b.png").string(), grey, {}, &t);
  EXPECT_GT(t.encode_sec, after_one.encode_sec);
  EXPECT_GT(t.write_sec, after_one.write_sec);
  // without a PngWriteTimes nothing is counted and the files are the same
  WritePngRgb8((dir.path() / "c.png").string(), rgb);
  EXPECT_EQ(ReadPng((dir.path() / "a.png").string()).samples,
            ReadPng((dir.path() / "c.png").string()).samples);
}

TEST(PngWriteTimes, AsyncFrameWriterSumsItsCameras) {
  TempDir dir;
  AsyncFrameWriter writer(dir.str());
  CameraOutputs outputs;
  outputs[ImageKind::kRgb] = outputs[ImageKind::kDepth] = true;
  writer.AddCamera("left", CameraIntrinsics::FromFovy(32, 24, 70), outputs);
  writer.AddCamera("right", CameraIntrinsics::FromFovy(32, 24, 70), outputs);
  EXPECT_EQ(writer.PngTimes().encode_sec, 0);
  EXPECT_EQ(writer.PngTimes().write_sec, 0);
  for (const char* camera : {"left", "right"}) {
    CameraFrame f;
    f.camera = camera;
    f.index = 0;
    f.rgb = ImageU8(32, 24, 3, 100);
    f.depth_m = ImageF(32, 24, 1, 1.5f);
    writer.Submit(std::move(f));
  }
  writer.Flush();
  const PngWriteTimes t = writer.PngTimes();
  EXPECT_GT(t.encode_sec, 0);
  EXPECT_GT(t.write_sec, 0);
}

}  // namespace
}  // namespace penumbra
