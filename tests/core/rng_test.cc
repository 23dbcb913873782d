// the counter-based random streams: random access equals sequential drawing.

#include "penumbra/core/rng.h"

#include <gtest/gtest.h>

#include <cstdint>

namespace penumbra {
namespace {

TEST(RngTest, DrawAtEqualsTheNthSequentialDraw) {
  for (const uint64_t stream : {uint64_t{0}, uint64_t{7}, HashKeys(3, 141, 59), ~uint64_t{0}}) {
    Rng rng(stream);
    for (uint64_t n = 0; n < 64; ++n) EXPECT_EQ(Rng::DrawAt(stream, n), rng.NextU64()) << n;
  }
}

TEST(RngTest, Uniform2TakesTheTop48BitsOfOneDraw) {
  Rng a(HashKeys(1, 2)), b(HashKeys(1, 2));
  for (int i = 0; i < 1000; ++i) {
    float u1, u2;
    a.Uniform2(&u1, &u2);
    const uint64_t z = b.NextU64();
    EXPECT_EQ(u1, static_cast<float>(z >> 40) * 0x1.0p-24f);
    EXPECT_EQ(u2, static_cast<float>((z >> 16) & 0xffffffULL) * 0x1.0p-24f);
    EXPECT_GE(u1, 0.0f);
    EXPECT_LT(u1, 1.0f);
    EXPECT_LT(u2, 1.0f);
  }
  // the all-ones draw gives the largest value below 1.
  float hi1, hi2;
  Rng::Uniform2Of(~uint64_t{0}, &hi1, &hi2);
  EXPECT_EQ(hi1, 1.0f - 0x1.0p-24f);
  EXPECT_EQ(hi2, 1.0f - 0x1.0p-24f);
}

}  // namespace
}  // namespace penumbra
