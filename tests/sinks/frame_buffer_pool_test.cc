#include "penumbra/sinks/frame_buffer_pool.h"

#include <gtest/gtest.h>

namespace penumbra {
namespace {

CameraFrame Written(const std::string& camera, int w, int h, uint8_t value) {
  CameraFrame f;
  f.camera = camera;
  f.index = 7;
  f.rgb = ImageU8(w, h, 3, value);
  f.depth_m = ImageF(w, h, 1, 2.5f);
  f.geom_id = ImageI32(w, h, 1, 4);
  f.range_m = ImageF(w, h, 1, 3.0f);
  f.normal_O = ImageF(w, h, 3, 0.5f);
  f.body_id = ImageI32(w, h, 1, 2);
  f.semantic_class = ImageI32(w, h, 1, 9);
  return f;
}

TEST(FrameBufferPool, TakeMovesAReturnedFramesImagesIntoTheirPlaces) {
  FrameBufferPool pool;
  CameraFrame f = Written("front", 8, 6, 200);
  const uint8_t* rgb_storage = f.rgb.data.data();
  pool.Return(std::move(f));
  EXPECT_EQ(pool.kept("front"), 1);

  CameraImages img;
  pool.Take("front", &img);
  EXPECT_EQ(pool.kept("front"), 0);
  // the same storage comes back (no copy), with its shape and last pixels
  EXPECT_EQ(img.rgb.data.data(), rgb_storage);
  EXPECT_EQ(img.rgb.width, 8);
  EXPECT_EQ(img.rgb.height, 6);
  EXPECT_EQ(img.rgb.data[0], 200);
  EXPECT_EQ(img.depth_m.data.size(), 48u);
  EXPECT_EQ(img.truth.geom_id.data[3], 4);
  EXPECT_EQ(img.truth.range_m.data[3], 3.0f);
  EXPECT_EQ(img.truth.normal_O.data.size(), 144u);
  EXPECT_EQ(img.truth.body_id.data[0], 2);
  EXPECT_EQ(img.truth.semantic_class.data[0], 9);
  // what the writer never gets is left alone
  EXPECT_TRUE(img.truth.radiance.data.empty());
  EXPECT_TRUE(img.truth.depth_m.data.empty());
}

TEST(FrameBufferPool, CamerasAreKeptApartAndEachIsBounded) {
  FrameBufferPool pool(2);
  for (int i = 0; i < 5; ++i) pool.Return(Written("front", 4, 4, static_cast<uint8_t>(i)));
  pool.Return(Written("rover/head", 2, 2, 9));
  EXPECT_EQ(pool.kept("front"), 2);
  EXPECT_EQ(pool.kept("rover/head"), 1);
  EXPECT_EQ(pool.kept("back"), 0);

  // a camera with nothing kept leaves the images as they are
  CameraImages img;
  img.rgb = ImageU8(3, 3, 3, 1);
  pool.Take("back", &img);
  EXPECT_EQ(img.rgb.width, 3);
  pool.Take("rover/head", &img);
  EXPECT_EQ(img.rgb.width, 2);
  EXPECT_EQ(img.rgb.data[0], 9);
  EXPECT_EQ(pool.kept("front"), 2);
}

TEST(FrameBufferPool, ZeroKeepsNothing) {
  FrameBufferPool pool(0);
  pool.Return(Written("front", 4, 4, 1));
  EXPECT_EQ(pool.kept("front"), 0);
  CameraImages img;
  pool.Take("front", &img);
  EXPECT_TRUE(img.rgb.data.empty());
}

}  // namespace
}  // namespace penumbra
