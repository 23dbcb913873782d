#include "penumbra/viewer/image_maps.h"

#include <gtest/gtest.h>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

TEST(ImageMapsTest, TurboFollowsThePublishedTable) {
  // Turbo's published table: 0.5 -> (0.644, 0.990, 0.237), 1 -> (0.480, 0.016, 0.011); the
  // polynomial fit stays within 0.1 of it
  auto near = [](std::array<uint8_t, 3> c, double r, double g, double b) {
    EXPECT_NEAR(c[0] / 255.0, r, 0.1);
    EXPECT_NEAR(c[1] / 255.0, g, 0.1);
    EXPECT_NEAR(c[2] / 255.0, b, 0.1);
  };
  near(TurboColor(0.5), 0.644, 0.990, 0.237);
  near(TurboColor(1.0), 0.480, 0.016, 0.011);
  const auto lo = TurboColor(0.05);  // the near end is blue
  EXPECT_GT(lo[2], 2 * lo[0]);
  EXPECT_EQ(TurboColor(-3), TurboColor(0));
  EXPECT_EQ(TurboColor(7), TurboColor(1));
}

TEST(ImageMapsTest, DepthRangeAndColours) {
  ImageF d(100, 1, 1);
  for (int u = 0; u < 100; ++u) d.data[u] = u == 0 ? 0.0f : 1.0f + 0.1f * u;  // 1.1 .. 10.9 m
  const DepthColorMap m = ColorizeDepth(d);
  EXPECT_NEAR(m.near_m, 1.1, 0.11);
  EXPECT_NEAR(m.far_m, 10.9, 0.11);
  // no hit: black; nearest: colour 0; farthest: colour 1
  EXPECT_EQ(m.image.data[0] + m.image.data[1] + m.image.data[2], 0);
  const auto c0 = TurboColor(0), c1 = TurboColor(1);
  EXPECT_NEAR(m.image.at(1, 0)[2], c0[2], 3);
  EXPECT_NEAR(m.image.at(99, 0)[0], c1[0], 3);
  // a flat image still has a positive range; an empty one is black with 0..1
  ImageF flat(4, 4, 1, 2.0f);
  const DepthColorMap f = ColorizeDepth(flat);
  EXPECT_GT(f.far_m, f.near_m);
  const DepthColorMap e = ColorizeDepth(ImageF(4, 4, 1, 0.0f));
  EXPECT_EQ(e.near_m, 0);
  EXPECT_EQ(e.far_m, 1);
  for (uint8_t v : e.image.data) EXPECT_EQ(v, 0);
}

TEST(ImageMapsTest, SegmentationOverlayBlendsHitsOnly) {
  ImageU8 rgb(2, 1, 3, 100);
  ImageI32 ids(2, 1, 1);
  ids.data = {-1, 7};
  const ImageU8 o = SegmentationOverlay(rgb, ids);
  EXPECT_EQ(o.at(0, 0)[0], 100);
  const auto c = SegmentColor(7);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(o.at(1, 0)[k], (100 + c[k]) / 2.0, 1);
  EXPECT_NE(SegmentColor(1), SegmentColor(2));
  EXPECT_EQ(SegmentColor(5), SegmentColor(5));
  EXPECT_THROW(SegmentationOverlay(rgb, ImageI32(3, 1, 1)), Error);
}

}  // namespace
}  // namespace penumbra
