#include "penumbra/render/cpu/shadow_window_lanes.h"

#include <vector>

#include "penumbra/render/light/shadow_window_math.h"
#include "penumbra/render/transport/realtime_visibility.h"

#if defined(__AVX512F__)
#include <immintrin.h>
#endif

namespace penumbra {

namespace {

// a tile's hits as the transport's window masks read them (cuda::ShadowWindowMask's Surfaces).
struct TileHitSurfaces {
  const bool* did_hit;
  const int* geom;
  const float *p, *n;
  bool Hit(int64_t k) const { return did_hit[k]; }
  int Geom(int64_t k) const { return geom[k]; }
  void Surface(int64_t k, float ng[3], float pk[3]) const {
    for (int a = 0; a < 3; ++a) ng[a] = n[3 * k + a], pk[a] = p[3 * k + a];
  }
};

}  // namespace

void SameSurfaceWindows(int width, int height, const bool* did_hit, const int* geom, const float* p,
                        const float* n, uint32_t* near) {
  const TileHitSurfaces s{did_hit, geom, p, n};
  const ShadowTile tile{0, 0, width, height};
  for (int y = 0, i = 0; y < height; ++y)
    for (int x = 0; x < width; ++x, ++i) near[i] = cuda::ShadowWindowMask(s, i, width, x, y, tile);
}

void SameSurfaceWindowsLanes(int width, int height, const bool* did_hit, const int* geom,
                             const float* p, const float* n, uint32_t* near) {
#if defined(__AVX512F__)
  // the hits as separate arrays (structure of arrays), kPad entries before the first pixel and
  // after the last, so that a row's window offsets load 16 neighbours at once; lanes outside the
  // tile are masked (never read).
  constexpr int kPad = 32;
  const int count = width * height;
  thread_local std::vector<float> soa;
  thread_local std::vector<int32_t> geoms;
  const size_t stride = static_cast<size_t>(count) + 2 * kPad;
  soa.resize(6 * stride);
  geoms.resize(stride);
  float* px = soa.data() + kPad;
  float* py = px + stride;
  float* pz = py + stride;
  float* nx = pz + stride;
  float* ny = nx + stride;
  float* nz = ny + stride;
  int32_t* g = geoms.data() + kPad;
  for (int i = 0; i < count; ++i) {
    px[i] = p[3 * i], py[i] = p[3 * i + 1], pz[i] = p[3 * i + 2];
    nx[i] = n[3 * i], ny[i] = n[3 * i + 1], nz[i] = n[3 * i + 2];
    g[i] = geom[i];
  }
  const __m512i lane = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  const __m512 cos_min = _mm512_set1_ps(0.9f), flat = _mm512_set1_ps(0.0025f),
               eps = _mm512_set1_ps(1e-10f);
  for (int y = 0; y < height; ++y) {
    for (int x0 = 0; x0 < width; x0 += 16) {
      const int i0 = y * width + x0;
      // lanes inside the row, and those that hit.
      const __mmask16 row = _mm512_cmplt_epi32_mask(_mm512_add_epi32(lane, _mm512_set1_epi32(x0)),
                                                    _mm512_set1_epi32(width));
      __mmask16 hit = 0;
      for (int k = 0; k < 16 && x0 + k < width; ++k)
        hit |= static_cast<__mmask16>(did_hit[i0 + k] ? 1u << k : 0u);
      const __m512 pix = _mm512_maskz_loadu_ps(row, px + i0),
                   piy = _mm512_maskz_loadu_ps(row, py + i0),
                   piz = _mm512_maskz_loadu_ps(row, pz + i0);
      const __m512 nix = _mm512_maskz_loadu_ps(row, nx + i0),
                   niy = _mm512_maskz_loadu_ps(row, ny + i0),
                   niz = _mm512_maskz_loadu_ps(row, nz + i0);
      const __m512i gi = _mm512_maskz_loadu_epi32(row, g + i0);
      __m512i bits = _mm512_maskz_mov_epi32(hit, _mm512_set1_epi32(1 << ShadowWindowBit(0, 0)));
      for (int dy = -2; dy <= 2; ++dy) {
        if (y + dy < 0 || y + dy >= height) continue;
        for (int dx = -2; dx <= 2; ++dx) {
          if (dx == 0 && dy == 0) continue;
          // lanes whose neighbour (x + dx, y + dy) lies inside the tile.
          const __m512i xn = _mm512_add_epi32(lane, _mm512_set1_epi32(x0 + dx));
          const __mmask16 in = hit & _mm512_cmpge_epi32_mask(xn, _mm512_setzero_si512()) &
                               _mm512_cmplt_epi32_mask(xn, _mm512_set1_epi32(width));
          if (in == 0) continue;
          const int j0 = i0 + dy * width + dx;
          const __m512i gj = _mm512_maskz_loadu_epi32(in, g + j0);
          __mmask16 same = _mm512_mask_cmpeq_epi32_mask(in, gi, gj);
          if (same == 0) continue;
          // SameShadowSurface: ng_i . ng_j >= 0.9, then (ng_i . dp)^2 <= 0.0025 |dp|^2 + 1e-10,
          // each dot product a0 b0 + (a1 b1 + a2 b2).
          const __m512 njx = _mm512_maskz_loadu_ps(same, nx + j0),
                       njy = _mm512_maskz_loadu_ps(same, ny + j0),
                       njz = _mm512_maskz_loadu_ps(same, nz + j0);
          const __m512 cos =
              _mm512_add_ps(_mm512_mul_ps(nix, njx),
                            _mm512_add_ps(_mm512_mul_ps(niy, njy), _mm512_mul_ps(niz, njz)));
          same = _mm512_mask_cmp_ps_mask(same, cos, cos_min, _CMP_GE_OQ);
          if (same == 0) continue;
          const __m512 dpx = _mm512_sub_ps(_mm512_maskz_loadu_ps(same, px + j0), pix);
          const __m512 dpy = _mm512_sub_ps(_mm512_maskz_loadu_ps(same, py + j0), piy);
          const __m512 dpz = _mm512_sub_ps(_mm512_maskz_loadu_ps(same, pz + j0), piz);
          const __m512 off =
              _mm512_add_ps(_mm512_mul_ps(nix, dpx),
                            _mm512_add_ps(_mm512_mul_ps(niy, dpy), _mm512_mul_ps(niz, dpz)));
          const __m512 len2 =
              _mm512_add_ps(_mm512_mul_ps(dpx, dpx),
                            _mm512_add_ps(_mm512_mul_ps(dpy, dpy), _mm512_mul_ps(dpz, dpz)));
          same = _mm512_mask_cmp_ps_mask(same, _mm512_mul_ps(off, off),
                                         _mm512_add_ps(_mm512_mul_ps(flat, len2), eps), _CMP_LE_OQ);
          bits = _mm512_mask_or_epi32(bits, same, bits,
                                      _mm512_set1_epi32(1 << ShadowWindowBit(dx, dy)));
        }
      }
      _mm512_mask_storeu_epi32(near + i0, row, bits);
    }
  }
#else
  SameSurfaceWindows(width, height, did_hit, geom, p, n, near);
#endif
}

}  // namespace penumbra
