#include "penumbra/viewer/jpeg_encoder.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

// a smooth gradient with a few hard edges, like a rendered frame
ImageU8 TestImage(int w, int h) {
  ImageU8 img(w, h, 3);
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      uint8_t* p = img.at(u, v);
      p[0] = static_cast<uint8_t>(255 * u / (w - 1));
      p[1] = static_cast<uint8_t>(255 * v / (h - 1));
      p[2] = (u / 40 + v / 40) % 2 ? 200 : 40;
    }
  return img;
}

double MeanAbsError(const ImageU8& a, const ImageU8& b) {
  double sum = 0;
  for (size_t i = 0; i < a.data.size(); ++i) sum += std::abs(int(a.data[i]) - int(b.data[i]));
  return sum / a.data.size();
}

TEST(JpegEncoderTest, RoundTripsWithinJpegError) {
  JpegEncoder enc;
  const ImageU8 img = TestImage(640, 480);
  const std::string q90 = enc.Encode(img, 90);
  ASSERT_GT(q90.size(), 4u);
  EXPECT_EQ(static_cast<unsigned char>(q90[0]), 0xFF);  // SOI marker
  EXPECT_EQ(static_cast<unsigned char>(q90[1]), 0xD8);
  const ImageU8 back = DecodeJpeg(q90);
  ASSERT_EQ(back.width, 640);
  ASSERT_EQ(back.height, 480);
  EXPECT_LT(MeanAbsError(img, back), 3.0);
  // lower quality: smaller file, larger error
  const std::string q30 = enc.Encode(img, 30);
  EXPECT_LT(q30.size(), q90.size());
  EXPECT_GT(MeanAbsError(img, DecodeJpeg(q30)), MeanAbsError(img, back));
  // the encoder is reusable and deterministic
  EXPECT_EQ(enc.Encode(img, 90), q90);
}

TEST(JpegEncoderTest, GreyImagesAndBadInput) {
  JpegEncoder enc;
  ImageU8 grey(64, 32, 1, 128);
  const ImageU8 back = DecodeJpeg(enc.Encode(grey, 80));
  EXPECT_EQ(back.width, 64);
  EXPECT_NEAR(back.data[0], 128, 2);
  EXPECT_THROW(enc.Encode(ImageU8(), 80), Error);
  EXPECT_THROW(enc.Encode(ImageU8(4, 4, 4), 80), Error);
  EXPECT_THROW(DecodeJpeg("not a jpeg"), Error);
}

TEST(AdaptiveJpegQualityTest, FollowsBudgetAndDrops) {
  AdaptiveJpegOptions o;
  o.min_quality = 30;
  o.max_quality = 90;
  o.initial_quality = 80;
  o.target_bytes_per_sec = 1e6;  // 50 kB per frame at 20 frames/s
  AdaptiveJpegQuality q(o);
  EXPECT_EQ(q.quality(), 80);
  q.Update(60000, 0.05, 0);  // over budget
  EXPECT_EQ(q.quality(), 75);
  q.Update(20000, 0.05, 0);  // well under: up
  EXPECT_EQ(q.quality(), 77);
  q.Update(40000, 0.05, 0);  // within: unchanged
  EXPECT_EQ(q.quality(), 77);
  q.Update(1000, 0.05, 3);  // a client dropped frames: down hard
  EXPECT_EQ(q.quality(), 67);
  for (int i = 0; i < 20; ++i) q.Update(1000, 0.05, 1);
  EXPECT_EQ(q.quality(), 30);  // clamped
  for (int i = 0; i < 50; ++i) q.Update(1000, 0.05, 0);
  EXPECT_EQ(q.quality(), 90);
  o.min_quality = 95;
  EXPECT_THROW(o.ValidateOrThrow(), ConfigError);
  o = AdaptiveJpegOptions{};
  o.target_bytes_per_sec = 0;
  EXPECT_THROW(AdaptiveJpegQuality{o}, ConfigError);
}

}  // namespace
}  // namespace penumbra
