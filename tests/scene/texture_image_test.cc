// texture images: 8-bit storage, mip levels averaged in linear light, sharing of identical
// images.

#include "penumbra/scene/texture_image.h"

#include <gtest/gtest.h>

#include <cmath>

#include "penumbra/core/error.h"
#include "penumbra/scene/scene_description.h"

namespace penumbra {
namespace {

double Decode(int code) {
  const double c = code / 255.0;
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

// n x n one-pixel checker of sRGB codes a and b.
std::vector<uint8_t> Checker(int n, uint8_t a, uint8_t b) {
  std::vector<uint8_t> rgb;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const uint8_t c = (x + y) % 2 ? b : a;
      rgb.insert(rgb.end(), {c, c, c});
    }
  return rgb;
}

TEST(TextureImageTest, SrgbEncodeInvertsDecodeAndRounds) {
  const float* decode = SrgbDecodeTable();
  for (int c = 0; c < 256; ++c) {
    EXPECT_FLOAT_EQ(decode[c], static_cast<float>(Decode(c))) << c;
    EXPECT_EQ(EncodeSrgb8(decode[c]), c) << c;
  }
  EXPECT_EQ(EncodeSrgb8(-1.0f), 0);
  EXPECT_EQ(EncodeSrgb8(2.0f), 255);
  EXPECT_EQ(EncodeSrgb8(std::nanf("")), 0);
  // linear 0.5 is code 187.5 -> 188 (IEC 61966-2-1 OETF: 1.055 0.5^(1/2.4) - 0.055 = 0.7354).
  EXPECT_EQ(EncodeSrgb8(0.5f), 188);
}

TEST(TextureImageTest, MipChainHalvesToOneTexelAndHoldsFourThirds) {
  const TextureImage im(64, 32, 1, std::vector<uint8_t>(64 * 32 * 3, 77));
  ASSERT_EQ(im.num_levels(), 7);  // 64x32, 32x16, 16x8, 8x4, 4x2, 2x1, 1x1
  EXPECT_EQ(im.level(1).width, 32);
  EXPECT_EQ(im.level(1).height, 16);
  EXPECT_EQ(im.level(5).width, 2);
  EXPECT_EQ(im.level(5).height, 1);
  EXPECT_EQ(im.level(6).width, 1);
  EXPECT_EQ(im.level(6).height, 1);
  // 8-bit RGB storage: 3 bytes per level-0 texel, ~4 with the whole chain.
  const double per_texel = static_cast<double>(im.bytes()) / (64 * 32);
  EXPECT_GE(per_texel, 3.0 * 4 / 3 - 1e-9);
  EXPECT_LE(per_texel, 4.01);
}

TEST(TextureImageTest, LevelsAverageInLinearLight) {
  // a one-texel black / white checker averages to linear 0.5 (code 188) in every level, not
  // to the sRGB mean 128 (linear 0.22), which would darken far textures.
  const TextureImage im(8, 8, 1, Checker(8, 0, 255));
  for (int l = 1; l < im.num_levels(); ++l)
    for (uint8_t b : im.level(l).rgb_srgb) EXPECT_EQ(b, 188) << "level " << l;
}

TEST(TextureImageTest, OddSizesKeepTheMean) {
  // 3 x 1: codes 0, 255, 255 -> level 1 is 1 x 1 holding linear 2/3, not a dropped texel.
  const TextureImage im(3, 1, 1, {0, 0, 0, 255, 255, 255, 255, 255, 255});
  ASSERT_EQ(im.num_levels(), 2);
  EXPECT_EQ(im.level(1).rgb_srgb[0], EncodeSrgb8(2.0f / 3.0f));
}

TEST(TextureImageTest, CubeFacesAreFilteredSeparately) {
  // six 2 x 2 faces of one solid code each: every level keeps each face's colour.
  std::vector<uint8_t> rgb;
  for (int f = 0; f < 6; ++f)
    for (int i = 0; i < 4; ++i) rgb.insert(rgb.end(), {static_cast<uint8_t>(40 * f), 7, 9});
  const TextureImage im(2, 12, 6, std::move(rgb));
  ASSERT_EQ(im.num_levels(), 2);
  EXPECT_EQ(im.level(1).width, 1);
  EXPECT_EQ(im.level(1).height, 1);
  ASSERT_EQ(im.level(1).rgb_srgb.size(), 18u);
  for (int f = 0; f < 6; ++f) EXPECT_EQ(im.level(1).rgb_srgb[3 * f], 40 * f) << f;
}

TEST(TextureImageTest, BadSizesThrow) {
  EXPECT_THROW(TextureImage(0, 1, 1, {}), Error);
  EXPECT_THROW(TextureImage(2, 2, 1, std::vector<uint8_t>(11)), Error);
  EXPECT_THROW(TextureImage(2, 10, 6, std::vector<uint8_t>(60)), Error);
}

TEST(TextureImageTest, StoreSharesIdenticalImages) {
  TextureStore store;
  const std::vector<uint8_t> a = Checker(16, 10, 200), b = Checker(16, 200, 10);
  const auto ia = store.Add({16, 16, 1, a.data(), a.size()});
  const auto ia2 = store.Add({16, 16, 1, a.data(), a.size()});
  const auto ib = store.Add({16, 16, 1, b.data(), b.size()});
  // same bytes under another shape are another image.
  const auto ic = store.Add({8, 32, 1, a.data(), a.size()});
  EXPECT_EQ(ia.get(), ia2.get());
  EXPECT_NE(ia.get(), ib.get());
  EXPECT_NE(ia.get(), ic.get());
  EXPECT_EQ(store.size(), 3);
  // a batch built on several threads: duplicates within it and of stored images are shared.
  const std::vector<uint8_t> c = Checker(16, 1, 2);
  const auto batch = store.AddAll({{16, 16, 1, c.data(), c.size()},
                                   {16, 16, 1, b.data(), b.size()},
                                   {16, 16, 1, c.data(), c.size()},
                                   {16, 16, 1, a.data(), a.size()}},
                                  3);
  ASSERT_EQ(batch.size(), 4u);
  EXPECT_EQ(batch[0].get(), batch[2].get());
  EXPECT_EQ(batch[1].get(), ib.get());
  EXPECT_EQ(batch[3].get(), ia.get());
  EXPECT_EQ(batch[0]->rgb_srgb(), c);
  EXPECT_EQ(store.size(), 4);

  std::vector<Texture> textures(4);
  textures[0].image = ia, textures[1].image = ia2, textures[2].image = ib;  // [3]: no image
  const TextureMemory m = CountTextureMemory(textures);
  EXPECT_EQ(m.textures, 3);
  EXPECT_EQ(m.images, 2);
  EXPECT_EQ(m.texels, 2u * 16 * 16);
  EXPECT_EQ(m.bytes, ia->bytes() + ib->bytes());
  EXPECT_LE(m.bytes_per_texel(), 4.01);
}

}  // namespace
}  // namespace penumbra
