// the anisotropic taps as SIMD lanes (BilinearWrapTapsLanes) give bit for bit what the shared
// scalar formula (BilinearWrapTaps) gives: random levels, coordinates, axes and tap counts,
// wrapping across every edge, the level's last texel, 1 x 1 levels and more than 16 taps. and
// the lookups of 4-byte texels (the CUDA backend's, render/cuda/realtime_shading.h's
// kRealtimeTexelBytes) give bit for bit what the same texels in 3 bytes give.

#include "penumbra/render/texture_lanes.h"

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

// the texels of a level w x h (x faces) in 4 bytes each: rgb and a fourth byte `pad` (the
// lookups ignore it).
std::vector<uint8_t> FourByteTexels(const std::vector<uint8_t>& rgb, uint8_t pad) {
  std::vector<uint8_t> out(rgb.size() / 3 * 4);
  for (size_t k = 0; k < rgb.size() / 3; ++k) {
    for (int c = 0; c < 3; ++c) out[4 * k + c] = rgb[3 * k + c];
    out[4 * k + 3] = pad;
  }
  return out;
}

// BilinearWrap, BilinearWrapTaps and BilinearFace of 4-byte texels (kTexelBytes 4: one 32-bit
// load a texel) against the same texels in 3 bytes: the same bits at random coordinates of
// random levels, whatever the fourth byte holds. the 4-byte texels read as 3-byte ones (the
// stride wrong) differ, so the comparison can fail.
TEST(TexelBytesTest, FourByteTexelsGiveTheThreeByteBits) {
  Rng rng(41);
  const float* decode = SrgbDecodeTable();
  const int sizes[][2] = {{1, 1}, {2, 1}, {1, 3}, {7, 5}, {64, 64}, {33, 257}};
  int checked = 0, wrong_stride_differs = 0;
  for (const auto& size : sizes) {
    const int w = size[0], h = size[1];
    // a 2d level, and six faces of w x w for the cube lookups
    std::vector<uint8_t> rgb(static_cast<size_t>(w) * h * 3),
        faces(static_cast<size_t>(w) * w * 18);
    for (uint8_t& b : rgb) b = static_cast<uint8_t>(rng.Uniform() * 256.0f);
    for (uint8_t& b : faces) b = static_cast<uint8_t>(rng.Uniform() * 256.0f);
    for (const uint8_t pad : {uint8_t{0}, uint8_t{255}}) {
      const std::vector<uint8_t> rgbx = FourByteTexels(rgb, pad);
      const std::vector<uint8_t> facesx = FourByteTexels(faces, pad);
      const TextureLevelView L3{rgb.data(), w, h}, L4{rgbx.data(), w, h};
      const TextureLevelView C3{faces.data(), w, w}, C4{facesx.data(), w, w};
      for (int i = 0; i < 500; ++i) {
        const float s = 6 * rng.Uniform() - 3, t = 6 * rng.Uniform() - 3;
        const float ds = 0.2f * (2 * rng.Uniform() - 1), dt = 0.2f * (2 * rng.Uniform() - 1);
        const int n = 1 + i % 8, face = i % 6;
        const float fs = rng.Uniform(), ft = rng.Uniform();
        const Float3 want = BilinearWrap<3>(L3, decode, s, t);
        ASSERT_TRUE(SameBits(want, BilinearWrap<4>(L4, decode, s, t)))
            << w << "x" << h << " s " << s << " t " << t;
        ASSERT_TRUE(SameBits(BilinearWrapTaps<3>(L3, decode, s, t, ds, dt, n),
                             BilinearWrapTaps<4>(L4, decode, s, t, ds, dt, n)))
            << w << "x" << h << " s " << s << " t " << t << " n " << n;
        ASSERT_TRUE(SameBits(BilinearFace<3>(C3, decode, face, fs, ft),
                             BilinearFace<4>(C4, decode, face, fs, ft)))
            << w << "x" << w << " face " << face << " s " << fs << " t " << ft;
        if (!SameBits(want, BilinearWrap<3>(L4, decode, s, t))) ++wrong_stride_differs;
        ++checked;
      }
    }
  }
  EXPECT_EQ(checked, 6 * 2 * 500);
  EXPECT_GT(wrong_stride_differs, checked / 2);
}

}  // namespace
}  // namespace penumbra
