// LDR-FLIP (eval/flip.h): identical images give 0 everywhere; pure green against pure blue is
// the model's largest colour difference (1); more noise gives a larger mean; the pooled values
// follow the FLIP tool's weighted-percentile rule; the magma heatmap's ends; bad inputs throw.
// the agreement with NVIDIA's own implementation is tests/eval/flip_reference_test.py.
#include "penumbra/eval/flip.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <random>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

ImageU8 Flat(int w, int h, uint8_t r, uint8_t g, uint8_t b) {
  ImageU8 image(w, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      uint8_t* p = image.at(x, y);
      p[0] = r;
      p[1] = g;
      p[2] = b;
    }
  return image;
}

// a gradient with two coloured boxes
ImageU8 Scene(int w, int h) {
  ImageU8 image(w, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      uint8_t* p = image.at(x, y);
      p[0] = static_cast<uint8_t>(255 * x / w);
      p[1] = static_cast<uint8_t>(255 * y / h);
      p[2] = 90;
      if (x > w / 4 && x < w / 2 && y > h / 4 && y < h / 2) p[0] = 200, p[1] = 40, p[2] = 30;
      if (x > 2 * w / 3 && y > h / 2) p[0] = 20, p[1] = 170, p[2] = 220;
    }
  return image;
}

ImageU8 Noisy(const ImageU8& image, int amplitude, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> d(-amplitude, amplitude);
  ImageU8 out = image;
  for (uint8_t& v : out.data) v = static_cast<uint8_t>(std::clamp(v + d(rng), 0, 255));
  return out;
}

TEST(FlipTest, IdenticalImagesGiveZeroEverywhere) {
  const ImageU8 a = Scene(96, 64);
  const ImageF map = FlipErrorMap(a, a);
  ASSERT_EQ(map.width, 96);
  ASSERT_EQ(map.height, 64);
  ASSERT_EQ(map.channels, 1);
  for (float v : map.data) ASSERT_EQ(v, 0.0f);
  const FlipStats s = PoolFlipErrors(map);
  EXPECT_EQ(s.mean, 0.0);
  EXPECT_EQ(s.max, 0.0);
  EXPECT_EQ(s.weighted_median, 0.0);
}

TEST(FlipTest, PureGreenAgainstPureBlueIsTheLargestColourDifference) {
  // flat images: no features, and green-blue is the distance FLIP's colour remap maps to 1
  const ImageF map = FlipErrorMap(Flat(40, 30, 0, 255, 0), Flat(40, 30, 0, 0, 255));
  for (float v : map.data) ASSERT_NEAR(v, 1.0f, 1e-5f);
  // black against white: far, but nearer than green-blue
  const ImageF bw = FlipErrorMap(Flat(40, 30, 0, 0, 0), Flat(40, 30, 255, 255, 255));
  EXPECT_GT(bw.data[0], 0.9f);
  EXPECT_LT(bw.data[0], 1.0f);
}

TEST(FlipTest, MoreNoiseGivesALargerMeanInZeroOne) {
  const ImageU8 a = Scene(96, 64);
  double previous = 0;
  for (int amplitude : {2, 8, 32, 96}) {
    const ImageF map = FlipErrorMap(a, Noisy(a, amplitude, 7));
    for (float v : map.data) {
      ASSERT_GE(v, 0.0f);
      ASSERT_LE(v, 1.0f);
    }
    const double mean = PoolFlipErrors(map).mean;
    EXPECT_GT(mean, previous) << "noise amplitude " << amplitude;
    previous = mean;
  }
}

TEST(FlipTest, AOnePixelChangeReachesOnlyTheFilterRadius) {
  // at 67.02 pixels per degree the colour kernel's radius is ceil(3 sqrt(0.04 / (2 pi^2)) 67.02)
  // = 10 pixels and the feature kernel's ceil(3 * 0.5 * 0.082 * 67.02) = 9
  const ImageU8 a = Flat(64, 48, 128, 128, 128);
  ImageU8 b = a;
  uint8_t* p = b.at(30, 20);
  p[0] = p[1] = p[2] = 255;
  const ImageF map = FlipErrorMap(a, b);
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 64; ++x) {
      const int d = std::max(std::abs(x - 30), std::abs(y - 20));
      const float v = map.data[static_cast<size_t>(y) * 64 + x];
      if (d > 10) {
        ASSERT_EQ(v, 0.0f) << x << "," << y;
      } else if (d <= 1) {
        ASSERT_GT(v, 0.1f) << x << "," << y;
      }
    }
}

TEST(FlipTest, DefaultPixelsPerDegreeIsFlipsMonitor) {
  EXPECT_NEAR(FlipPixelsPerDegree(0.7, 3840, 0.7), kFlipDefaultPixelsPerDegree, 1e-12);
  EXPECT_NEAR(kFlipDefaultPixelsPerDegree, 67.0206, 1e-4);
}

TEST(FlipTest, PoolingUsesTheWeightedPercentileRule) {
  ImageF map(4, 1, 1);
  map.data = {0.4f, 0.1f, 0.3f, 0.2f};
  const FlipStats s = PoolFlipErrors(map);
  EXPECT_NEAR(s.mean, 0.25, 1e-7);
  EXPECT_FLOAT_EQ(s.min, 0.1f);
  EXPECT_FLOAT_EQ(s.max, 0.4f);
  // sorted 0.1 0.2 0.3 0.4, sum 1: running sums 0.1 0.3 0.6 1.0
  EXPECT_FLOAT_EQ(s.weighted_q1, 0.2f);      // first running sum > 0.25
  EXPECT_FLOAT_EQ(s.weighted_median, 0.3f);  // > 0.5
  EXPECT_FLOAT_EQ(s.weighted_q3, 0.4f);      // > 0.75
}

TEST(FlipTest, MagmaHeatmapEnds) {
  ImageF map(3, 1, 1);
  map.data = {0.0f, 0.5f, 1.0f};
  const ImageU8 heat = FlipMagmaHeatmap(map);
  ASSERT_EQ(heat.channels, 3);
  // magma: near-black purple at 0, pale yellow at 1, entry 128 at 0.5
  EXPECT_EQ(heat.at(0, 0)[0], 0);
  EXPECT_EQ(heat.at(0, 0)[2], 4);
  EXPECT_EQ(heat.at(2, 0)[0], 252);
  EXPECT_EQ(heat.at(2, 0)[1], 253);
  EXPECT_EQ(heat.at(2, 0)[2], 191);
  const std::array<float, 3> mid = FlipMagmaColour(128);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(heat.at(1, 0)[c], std::lround(255 * mid[c]));
  EXPECT_THROW(FlipMagmaColour(256), Error);
}

TEST(FlipTest, BadInputsThrow) {
  const ImageU8 a = Flat(8, 8, 1, 2, 3);
  EXPECT_THROW(FlipErrorMap(a, Flat(8, 9, 1, 2, 3)), Error);
  EXPECT_THROW(FlipErrorMap(a, ImageU8(8, 8, 4)), Error);
  EXPECT_THROW(FlipErrorMap(ImageU8(), ImageU8()), Error);
  EXPECT_THROW(FlipErrorMap(a, a, 0.0), Error);
  EXPECT_THROW(FlipErrorMap(a, a, kFlipMaxPixelsPerDegree * 2), Error);
  EXPECT_THROW(FlipErrorMap(a, a, std::nan("")), Error);
  EXPECT_THROW(PoolFlipErrors(ImageF(2, 2, 3)), Error);
}

}  // namespace
}  // namespace penumbra
