#pragma once
// the anisotropic taps of a texture lookup (BilinearWrapTaps, render/material/texture_math.h) with
// up to 16 taps as SIMD lanes, for the CPU: every tap's coordinates, wrapped texels, byte offsets
// and bilinear weights at once (AVX-512, one register per quantity), then the texels read, decoded
// by table and summed tap after tap as the shared formula does. the result is bit-identical to
// BilinearWrapTaps (the same IEEE operations on the same values in the same order; the build
// compiles with -ffp-contract=off, so nothing is fused). the texel reads stay scalar: AVX-512
// gathers of the bytes and of the decode table were measured slower than scalar loads on the
// development machine's AMD EPYC (docs/performance.md, "Texture taps as lanes"). without
// AVX-512 it is BilinearWrapTaps itself; the GPU keeps the shared scalar formula.

#include <cstdint>

#include "penumbra/render/material/texture_math.h"

#if defined(__AVX512F__)
#include <immintrin.h>
#endif

namespace penumbra {

/// BilinearWrapTaps(L, decode, s, t, ds, dt, n) (render/material/texture_math.h), bit-identical,
/// with the taps as SIMD lanes (file comment). n >= 1.
inline Float3 BilinearWrapTapsLanes(const TextureLevelView& L, const float* decode, float s,
                                    float t, float ds, float dt, int n) {
#if defined(__AVX512F__)
  const int w = L.width, h = L.height;
  // levels whose byte offsets do not fit 31 bits, and more than 16 taps, take the scalar formula.
  const int64_t bytes = static_cast<int64_t>(w) * h * 3;
  if (n > 16 || bytes > (int64_t{1} << 30)) return BilinearWrapTaps(L, decode, s, t, ds, dt, n);
  const float step = 1.0f / static_cast<float>(n);
  const float o0 = 0.5f * step - 0.5f;
  const __m512 k = _mm512_setr_ps(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  // o = o0 + k step; (u, v) = (s, t) + o (ds, dt) (BilinearWrapTaps).
  const __m512 o = _mm512_add_ps(_mm512_set1_ps(o0), _mm512_mul_ps(k, _mm512_set1_ps(step)));
  const __m512 u = _mm512_add_ps(_mm512_set1_ps(s), _mm512_mul_ps(o, _mm512_set1_ps(ds)));
  const __m512 v = _mm512_add_ps(_mm512_set1_ps(t), _mm512_mul_ps(o, _mm512_set1_ps(dt)));
  // WrapTexels: x = (u - floor(u)) w - 0.5, x0 = floor(x), fx = x - x0, wrapped by one step.
  constexpr int kFloor = _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC;
  const __m512 half = _mm512_set1_ps(0.5f);
  const __m512 x = _mm512_sub_ps(_mm512_mul_ps(_mm512_sub_ps(u, _mm512_roundscale_ps(u, kFloor)),
                                               _mm512_set1_ps(static_cast<float>(w))),
                                 half);
  const __m512 y = _mm512_sub_ps(_mm512_mul_ps(_mm512_sub_ps(v, _mm512_roundscale_ps(v, kFloor)),
                                               _mm512_set1_ps(static_cast<float>(h))),
                                 half);
  const __m512 x0f = _mm512_roundscale_ps(x, kFloor), y0f = _mm512_roundscale_ps(y, kFloor);
  const __m512 fx = _mm512_sub_ps(x, x0f), fy = _mm512_sub_ps(y, y0f);
  const __m512i wv = _mm512_set1_epi32(w), hv = _mm512_set1_epi32(h);
  const __m512i one = _mm512_set1_epi32(1), zero = _mm512_setzero_si512();
  __m512i x0 = _mm512_cvttps_epi32(x0f), y0 = _mm512_cvttps_epi32(y0f);
  __m512i x1 = _mm512_add_epi32(x0, one), y1 = _mm512_add_epi32(y0, one);
  x0 = _mm512_mask_add_epi32(x0, _mm512_cmplt_epi32_mask(x0, zero), x0, wv);
  y0 = _mm512_mask_add_epi32(y0, _mm512_cmplt_epi32_mask(y0, zero), y0, hv);
  x1 = _mm512_mask_sub_epi32(x1, _mm512_cmpge_epi32_mask(x1, wv), x1, wv);
  y1 = _mm512_mask_sub_epi32(y1, _mm512_cmpge_epi32_mask(y1, hv), y1, hv);
  // byte offsets of the four texels: (y w + x) 3.
  const __m512i three = _mm512_set1_epi32(3);
  const __m512i row0 = _mm512_mullo_epi32(y0, wv), row1 = _mm512_mullo_epi32(y1, wv);
  const __m512i off[4] = {_mm512_mullo_epi32(_mm512_add_epi32(row0, x0), three),
                          _mm512_mullo_epi32(_mm512_add_epi32(row0, x1), three),
                          _mm512_mullo_epi32(_mm512_add_epi32(row1, x0), three),
                          _mm512_mullo_epi32(_mm512_add_epi32(row1, x1), three)};
  // w00 = (1 - fx)(1 - fy), w10 = fx (1 - fy), w01 = (1 - fx) fy, w11 = fx fy.
  const __m512 one_f = _mm512_set1_ps(1.0f);
  const __m512 gx = _mm512_sub_ps(one_f, fx), gy = _mm512_sub_ps(one_f, fy);
  alignas(64) float wt[4][16];
  alignas(64) int32_t at[4][16];
  _mm512_store_ps(wt[0], _mm512_mul_ps(gx, gy));
  _mm512_store_ps(wt[1], _mm512_mul_ps(fx, gy));
  _mm512_store_ps(wt[2], _mm512_mul_ps(gx, fy));
  _mm512_store_ps(wt[3], _mm512_mul_ps(fx, fy));
  for (int q = 0; q < 4; ++q) _mm512_store_si512(at[q], off[q]);
  // the taps' texels decoded by table and summed in the shared formula's order.
  const uint8_t* p = L.rgb;
  float r = 0, g = 0, b = 0;
  for (int i = 0; i < n; ++i) {
    const uint8_t* a = p + at[0][i];
    const uint8_t* bq = p + at[1][i];
    const uint8_t* c = p + at[2][i];
    const uint8_t* d = p + at[3][i];
    const float w00 = wt[0][i], w10 = wt[1][i], w01 = wt[2][i], w11 = wt[3][i];
    r += w00 * decode[a[0]] + w10 * decode[bq[0]] + w01 * decode[c[0]] + w11 * decode[d[0]];
    g += w00 * decode[a[1]] + w10 * decode[bq[1]] + w01 * decode[c[1]] + w11 * decode[d[1]];
    b += w00 * decode[a[2]] + w10 * decode[bq[2]] + w01 * decode[c[2]] + w11 * decode[d[2]];
  }
  return Float3{r, g, b} * step;
#else
  return BilinearWrapTaps(L, decode, s, t, ds, dt, n);
#endif
}

}  // namespace penumbra
