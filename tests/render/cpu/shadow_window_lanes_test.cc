// the same-surface window masks with a tile row's pixels as SIMD lanes (SameSurfaceWindowsLanes)
// equal the scalar definition (SameSurfaceWindows) word for word: random tiles of several sizes
// (up to the 28-pixel rows the shared visibility allows) made of a few planes, with misses,
// geom -1 hits, near-threshold normals and offsets.

#include "penumbra/render/cpu/shadow_window_lanes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "penumbra/core/rng.h"
#include "penumbra/render/light/shadow_window_math.h"

namespace penumbra {
namespace {

TEST(ShadowWindowLanesTest, LanesEqualTheScalarMasks) {
  Rng rng(41);
  const int sizes[][2] = {{16, 16}, {1, 1}, {5, 3}, {16, 7}, {17, 9}, {28, 28}, {3, 20}};
  int set_bits = 0, words = 0;
  for (const auto& size : sizes) {
    const int w = size[0], h = size[1], count = w * h;
    for (int trial = 0; trial < 300; ++trial) {
      std::vector<uint8_t> hit_bytes(count);
      std::vector<int> geom(count);
      std::vector<float> p(3 * count), n(3 * count);
      // a few planes: pixels left of a random column see plane 0, the others plane 1 or 2;
      // normals are perturbed around the plane's, points lie on the plane plus some noise.
      const int split = static_cast<int>(rng.Uniform() * w);
      const float noise = trial % 3 == 0 ? 0.0f : (trial % 3 == 1 ? 1e-3f : 3e-2f);
      for (int y = 0, i = 0; y < h; ++y)
        for (int x = 0; x < w; ++x, ++i) {
          hit_bytes[i] = rng.Uniform() < 0.9f;
          const int plane = x < split ? 0 : (rng.Uniform() < 0.8f ? 1 : 2);
          geom[i] = !hit_bytes[i] || rng.Uniform() < 0.05f ? -1 : (plane == 2 ? 7 : 3);
          const float nz = plane == 0 ? 1.0f : 0.8f;
          const float nx = std::sqrt(1 - nz * nz) + noise * (rng.Uniform() - 0.5f) * 10;
          n[3 * i] = nx, n[3 * i + 1] = noise * (rng.Uniform() - 0.5f), n[3 * i + 2] = nz;
          const float px = 0.01f * x, py = 0.01f * y;
          p[3 * i] = px, p[3 * i + 1] = py;
          p[3 * i + 2] = -(nx * px) / nz + noise * (rng.Uniform() - 0.5f);
        }
      std::unique_ptr<bool[]> did_hit(new bool[count]);
      for (int i = 0; i < count; ++i) did_hit[i] = hit_bytes[i] != 0;
      std::vector<uint32_t> want(count, 0xdeadbeefu), got(count, 0xdeadbeefu);
      SameSurfaceWindows(w, h, did_hit.get(), geom.data(), p.data(), n.data(), want.data());
      SameSurfaceWindowsLanes(w, h, did_hit.get(), geom.data(), p.data(), n.data(), got.data());
      for (int i = 0; i < count; ++i) {
        ASSERT_EQ(got[i], want[i]) << w << "x" << h << " trial " << trial << " pixel " << i;
        set_bits += __builtin_popcount(want[i]);
        words += want[i] != 0;
      }
    }
  }
  // the masks are neither empty nor full: windows straddle surfaces.
  EXPECT_GT(set_bits, 2 * words);
  EXPECT_LT(set_bits, 25 * words);
}

// the scalar definition on a known tile: a 5 x 5 plane with one missed pixel and one pixel of
// another geom; the centre pixel's window holds every pixel but those two.
TEST(ShadowWindowLanesTest, ScalarMasksOnAKnownTile) {
  const int w = 5, h = 5, count = w * h;
  bool did_hit[count];
  int geom[count];
  float p[3 * count], n[3 * count];
  for (int i = 0; i < count; ++i) {
    did_hit[i] = i != 3;
    geom[i] = i == 3 ? -1 : (i == 21 ? 2 : 1);
    p[3 * i] = 0.01f * (i % w), p[3 * i + 1] = 0.01f * (i / w), p[3 * i + 2] = 0;
    n[3 * i] = 0, n[3 * i + 1] = 0, n[3 * i + 2] = 1;
  }
  uint32_t near[count], lanes[count];
  SameSurfaceWindows(w, h, did_hit, geom, p, n, near);
  SameSurfaceWindowsLanes(w, h, did_hit, geom, p, n, lanes);
  const uint32_t all = (1u << 25) - 1;
  EXPECT_EQ(near[12], all & ~(1u << ShadowWindowBit(1, -2)) & ~(1u << ShadowWindowBit(-1, 2)));
  EXPECT_EQ(near[3], 0u);                            // missed
  EXPECT_EQ(near[21], 1u << ShadowWindowBit(0, 0));  // alone on its geom
  for (int i = 0; i < count; ++i) EXPECT_EQ(lanes[i], near[i]) << i;
}

}  // namespace
}  // namespace penumbra
