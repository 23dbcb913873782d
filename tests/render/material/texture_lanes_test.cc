// the anisotropic taps as SIMD lanes (BilinearWrapTapsLanes) give bit for bit what the shared
// scalar formula (BilinearWrapTaps) gives: random levels, coordinates, axes and tap counts,
// wrapping across every edge, the level's last texel, 1 x 1 levels and more than 16 taps.

#include "penumbra/render/material/texture_lanes.h"

#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "penumbra/core/rng.h"
#include "penumbra/scene/texture_image.h"

namespace penumbra {
namespace {

// true when a and b hold the same bits in every channel.
bool SameBits(const Float3& a, const Float3& b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(TextureLanesTest, TapsAreBitIdenticalToTheScalarFormula) {
  Rng rng(37);
  const float* decode = SrgbDecodeTable();
  const int sizes[][2] = {{1, 1}, {2, 1}, {1, 3}, {7, 5}, {64, 64}, {256, 128}, {33, 257}};
  int checked = 0;
  for (const auto& size : sizes) {
    const int w = size[0], h = size[1];
    std::vector<uint8_t> texels(static_cast<size_t>(w) * h * 3);
    for (uint8_t& b : texels) b = static_cast<uint8_t>(rng.Uniform() * 256.0f);
    const TextureLevelView level{texels.data(), w, h};
    for (int i = 0; i < 4000; ++i) {
      // coordinates over several images (wrapping both ways), axes from tiny to several images,
      // 1 to 20 taps (above 16: the scalar formula).
      const float s = 6 * rng.Uniform() - 3, t = 6 * rng.Uniform() - 3;
      const float scale = i % 3 == 0 ? 1e-3f : (i % 3 == 1 ? 0.1f : 4.0f);
      const float ds = scale * (2 * rng.Uniform() - 1), dt = scale * (2 * rng.Uniform() - 1);
      const int n = 1 + i % 20;
      const Float3 want = BilinearWrapTaps(level, decode, s, t, ds, dt, n);
      const Float3 got = BilinearWrapTapsLanes(level, decode, s, t, ds, dt, n);
      ASSERT_TRUE(SameBits(want, got))
          << w << "x" << h << " s " << s << " t " << t << " ds " << ds << " dt " << dt << " n " << n
          << ": scalar (" << want.x << ", " << want.y << ", " << want.z << ") lanes (" << got.x
          << ", " << got.y << ", " << got.z << ")";
      ++checked;
    }
  }
  EXPECT_EQ(checked, 7 * 4000);
}

// taps that land exactly on texel centres, image edges and the level's last texel (the
// coordinates where floor and the wrap steps decide), and negative zero.
TEST(TextureLanesTest, TapsOnTexelCentresAndEdgesAreBitIdentical) {
  const float* decode = SrgbDecodeTable();
  const int w = 8, h = 4;
  std::vector<uint8_t> texels(static_cast<size_t>(w) * h * 3);
  for (size_t k = 0; k < texels.size(); ++k) texels[k] = static_cast<uint8_t>(37 * k + 11);
  const TextureLevelView level{texels.data(), w, h};
  const float coords[] = {-1.0f,   -0.5f, -0.0f,        0.0f,   0.0625f, 0.5f,
                          0.9375f, 1.0f,  1.0f - 1e-7f, -1e-9f, 2.0f};
  for (float s : coords)
    for (float t : coords)
      for (int n : {1, 2, 3, 16}) {
        const float d[][2] = {{0, 0}, {0.125f, 0}, {0, 0.25f}, {-1.0f, 1.0f}};
        for (const auto& dd : d)
          ASSERT_TRUE(SameBits(BilinearWrapTaps(level, decode, s, t, dd[0], dd[1], n),
                               BilinearWrapTapsLanes(level, decode, s, t, dd[0], dd[1], n)))
              << "s " << s << " t " << t << " n " << n;
      }
}

}  // namespace
}  // namespace penumbra
