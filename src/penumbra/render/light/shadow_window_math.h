#pragma once
// the realtime tier's shared shadow verdicts for lights with an extent (sphere lamps, the sun's
// disc) as formulas both backends call (PB_HOST_DEVICE, core/host_device.h;
// the shared shading contract: Eigen-free, no std:: containers). a pixel's visibility of such
// a light is the ratio estimator of Heitz, Hill and McGuire, "Combining Analytic Direct
// Illumination and Stochastic Shadows" (I3D 2018) with the shadow term shared: the weighted
// fraction of visible shadow rays over the 5x5 pixels around it that lie on the same surface
// (same geom, normals within 25 degrees, within 5 % of their distance from its tangent plane),
// the window cut at the edges of the renderer's 16x16 pixel tiles. render/cpu/
// realtime_integrator.cc (ResolveSharedVisibility) and the CUDA path
// (render/transport/realtime_visibility.h, SharedVisibility*) apply it.

#include <cstdint>

#include "penumbra/core/host_device.h"

namespace penumbra {

/// side of the square pixel tiles whose edges cut the windows (EmbreeRenderer::kTileSize).
constexpr int kShadowTileSize = 16;
/// the window reaches this many pixels on each side (5x5).
constexpr int kShadowWindowRadius = 2;

/// the tile of pixel (u, v) in a width x height image: first column and row, size.
struct ShadowTile {
  int x0 = 0, y0 = 0, width = 0, height = 0;
};

/// the kShadowTileSize tile that holds pixel (u, v) (cut at the image's right and bottom edges).
PB_HOST_DEVICE inline ShadowTile ShadowTileOf(int u, int v, int width, int height) {
  ShadowTile t;
  t.x0 = u - u % kShadowTileSize;
  t.y0 = v - v % kShadowTileSize;
  t.width = width - t.x0 < kShadowTileSize ? width - t.x0 : kShadowTileSize;
  t.height = height - t.y0 < kShadowTileSize ? height - t.y0 : kShadowTileSize;
  return t;
}

/// the index of the lowest set bit of b != 0 (walks a window mask in row-major order).
PB_HOST_DEVICE inline int LowestSetBit(uint32_t b) {
#ifdef __CUDA_ARCH__
  return __ffs(static_cast<int>(b)) - 1;
#else
  return __builtin_ctz(b);
#endif
}

/// the bit of window offset (dx, dy), |dx|, |dy| <= kShadowWindowRadius, in a window mask.
PB_HOST_DEVICE inline int ShadowWindowBit(int dx, int dy) { return (dy + 2) * 5 + dx + 2; }

/// the weight of window offset (dx, dy): 1/2 on the outer rows and columns, so that each
/// pixel of a 4x4 lattice block weighs 1.
PB_HOST_DEVICE inline float ShadowWindowWeight(int dx, int dy) {
  return (dy == -2 || dy == 2 ? 0.5f : 1.0f) * (dx == -2 || dx == 2 ? 0.5f : 1.0f);
}

/// the taps of a window mask (bits 0 .. 24, ShadowWindowBit).
constexpr int kShadowWindowTaps = (2 * kShadowWindowRadius + 1) * (2 * kShadowWindowRadius + 1);

/// 4 ShadowWindowWeight(dx, dy) as an integer: 1 in the corners, 2 on the rest of the outer
/// rows and columns, 4 inside (64 over the whole window).
PB_HOST_DEVICE constexpr uint32_t ShadowWindowWeight4(int dx, int dy) {
  return (dy == -2 || dy == 2 ? 1u : 2u) * (dx == -2 || dx == 2 ? 1u : 2u);
}

/// one pixel's shadow-ray counts towards a light as the window sums add them
/// (ShadowWindowSumFraction): its traced rays `rays` (its own verdict and its penumbra rays: 1
/// to 64, PenumbraLatticePoints) in bits 16-31, its visible ones `visible` (0 to rays) in bits
/// 0-15; 0 for a pixel without a verdict (`vis` < 0), which the sums leave out. visible and
/// rays are whole numbers held in floats (integer counts), so the conversion is exact.
PB_HOST_DEVICE inline uint32_t ShadowWindowCounts(int vis, float visible, float rays) {
  return vis < 0 ? 0u : static_cast<uint32_t>(rays) << 16 | static_cast<uint32_t>(visible);
}

/// the fraction of visible rays of a sum of ShadowWindowWeight4-weighted ShadowWindowCounts
/// (or of one pixel's counts): visible over traced. why the integers give the bits of the float
/// sums sum(w visible) / sum(w rays) (w = ShadowWindowWeight: 1/4, 1/2 or 1) in any order: every
/// w rays is a multiple of 1/4 at most 64 and the weights total 16, so every partial sum is a
/// multiple of 1/4 at most 1,024 (12 significant bits, exact in a float's 24), and each float
/// sum is exactly the integer sum over 4; (A / 4) / (B / 4) rounds as A / B, and A, B <= 4,096
/// convert exactly. the halves never carry into each other (4,096 < 2^16).
PB_HOST_DEVICE inline float ShadowWindowSumFraction(uint32_t sum) {
  return static_cast<float>(sum & 0xffffu) / static_cast<float>(sum >> 16);
}

/// whether the hit g (geom, unit normal ng_g facing the ray, point p_g) lies on the surface of
/// hit i: the same geom, normals within 25 degrees (dot >= 0.9) and g within 5 % of its
/// distance from i's tangent plane. points in m, world frame. the sums run x + (y + z), the
/// order of Eigen's 3-vector dot and squaredNorm, which the CPU backend used before.
PB_HOST_DEVICE inline bool SameShadowSurface(int geom_i, const float ng_i[3], const float p_i[3],
                                             int geom_g, const float ng_g[3], const float p_g[3]) {
  if (geom_g != geom_i || !(ng_i[0] * ng_g[0] + (ng_i[1] * ng_g[1] + ng_i[2] * ng_g[2]) >= 0.9f))
    return false;
  const float dp[3] = {p_g[0] - p_i[0], p_g[1] - p_i[1], p_g[2] - p_i[2]};
  const float off = ng_i[0] * dp[0] + (ng_i[1] * dp[1] + ng_i[2] * dp[2]);
  return off * off <= 0.0025f * (dp[0] * dp[0] + (dp[1] * dp[1] + dp[2] * dp[2])) + 1e-10f;
}

/// a shadow tile's verdicts towards one light as bit rows (the GPU's VisibilityRaysWarpKernel
/// builds them with two ballots a warp): word y + kShadowWindowRadius of kShadowVerdictRows holds
/// tile row y, bit x set where pixel x's verdict is 1 (visible), bit kShadowTileSize + x where it
/// is 0 (occluded), neither where it has none (-1) or lies outside the image; the first and last
/// kShadowWindowRadius words stay 0, so that a window's rows above and below the tile read no
/// verdict.
constexpr int kShadowVerdictRows = kShadowTileSize + 2 * kShadowWindowRadius;

/// the bits of verdict `vis` (1, 0 or -1) of tile column x in a ShadowVerdictRow word.
PB_HOST_DEVICE inline uint32_t ShadowVerdictBits(int x, int vis) {
  return vis > 0 ? 1u << x : vis == 0 ? 1u << (kShadowTileSize + x) : 0u;
}

/// the verdict of tile pixel (x, y) in its tile's bit rows `rows` (kShadowVerdictRows words):
/// 1, 0 or -1.
PB_HOST_DEVICE inline int ShadowRowVerdict(const uint32_t* rows, int x, int y) {
  const uint32_t r = rows[y + kShadowWindowRadius];
  return (r >> x & 1u) != 0 ? 1 : (r >> (kShadowTileSize + x) & 1u) != 0 ? 0 : -1;
}

/// whether the window mask `bits` (ShadowWindowBit; cut at the tile's edges) of tile pixel (x,
/// y) holds a verdict 1 (seen[1]) and a verdict 0 (seen[0]), from the tile's bit rows `rows`:
/// window row dy's five bits against tile row y + dy shifted so that column x + dx lands on bit
/// dx + 2. the same booleans as testing the verdict of every set bit in turn.
PB_HOST_DEVICE inline void ShadowWindowVerdicts(const uint32_t* rows, int x, int y, uint32_t bits,
                                                bool seen[2]) {
  constexpr uint32_t kHalf = (1u << kShadowTileSize) - 1u;
  uint32_t ones = 0, zeros = 0;
#if defined(__CUDA_ARCH__)
#pragma unroll
#endif
  for (int r = 0; r <= 2 * kShadowWindowRadius; ++r) {
    const uint32_t w = bits >> (5 * r) & 31u;
    const uint32_t row = rows[y + r];  // tile row y + r - kShadowWindowRadius
    ones |= ((row & kHalf) << kShadowWindowRadius >> x) & w;
    zeros |= ((row >> kShadowTileSize) << kShadowWindowRadius >> x) & w;
  }
  seen[1] = ones != 0;
  seen[0] = zeros != 0;
}

/// whether tile-local pixel (x, y) lies on its tile's outermost ring (its window lacks the next
/// tile's half: in a penumbra it traces the whole lattice and keeps its own fraction).
PB_HOST_DEVICE inline bool OnShadowTileRing(int x, int y, const ShadowTile& t) {
  return x == 0 || y == 0 || x == t.width - 1 || y == t.height - 1;
}

}  // namespace penumbra
