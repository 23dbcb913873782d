#include "penumbra/render/film/film.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

#include "penumbra/core/srgb.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace penumbra {
namespace {

constexpr int kLutSize = kFilmLutSize;

inline float Luminance(const float* c) { return pbm::Luminance709(c[0], c[1], c[2]); }

inline int LutIndex(float x) { return FilmLutIndex(x); }

// table indices of n exposed values src[i] * exposure clamped to [0, 1] (the linear tone map).
// with SSE2, four at a time, with the same IEEE operations in the same order and the same NaN
// handling as the scalar form (min/max operand order as in std::clamp), so the indices are
// identical.
void ClampIndices(const float* src, int n, float exposure, int32_t* index) {
  int i = 0;
#if defined(__SSE2__)
  const __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.0f), ex = _mm_set1_ps(exposure);
  const __m128 scale = _mm_set1_ps(kLutSize - 1), half = _mm_set1_ps(0.5f);
  for (; i + 4 <= n; i += 4) {
    __m128 x = _mm_mul_ps(_mm_loadu_ps(src + i), ex);
    x = _mm_min_ps(one, _mm_max_ps(zero, x));  // std::clamp(x, 0, 1)
    // x > 0 ? x (kLutSize - 1) + 0.5 : 0, then the truncating conversion (x <= 1 here).
    const __m128 k = _mm_and_ps(_mm_cmpgt_ps(x, zero), _mm_add_ps(_mm_mul_ps(x, scale), half));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(index + i), _mm_cvttps_epi32(k));
  }
#endif
  for (; i < n; ++i) index[i] = LutIndex(std::clamp(src[i] * exposure, 0.0f, 1.0f));
}

// table indices of n / 3 exposed RGB pixels src * exposure[c] (white balance gains folded in)
// through the shared per-pixel map (DevelopPixelIndices, render/film/film_math.h); n a multiple
// of 3.
void PixelIndices(const float* src, int n, const float exposure[3], bool filmic, int32_t* index) {
  for (int i = 0; i + 3 <= n; i += 3) DevelopPixelIndices(src + i, exposure, filmic, index + i);
}

// sum over the n pixels of an RGB row of ln(max(L, kMinLuminance)), L the Rec. 709 luminance,
// as the logarithm of their product: the product's binary exponent and mantissa are kept apart
// (four interleaved partial products), and ln is taken once per row. exact but for the
// rounding of the mantissa products (~1e-16 relative each).
double SumLog(const float* rgb, int n) {
  constexpr uint64_t kMantissaBits = 0x000fffffffffffffull, kOne = 0x3ff0000000000000ull;
  double mantissa[4] = {1.0, 1.0, 1.0, 1.0};
  double odd = 0.0;  // sum of the logs of non-finite luminances
  int64_t exponent = 0;
  // splits x > 0 (a normal double) into f in [1, 2) and its binary exponent.
  auto split = [&](double x) {
    const uint64_t bits = std::bit_cast<uint64_t>(x);
    exponent += static_cast<int64_t>(bits >> 52) - 1023;
    return std::bit_cast<double>((bits & kMantissaBits) | kOne);
  };
  for (int i = 0; i < n; ++i) {
    const double L = std::max(static_cast<double>(Luminance(rgb + 3 * i)), kMinLuminance);
    if (!(L < std::numeric_limits<double>::infinity())) {
      odd += std::log(L);  // inf or NaN, as the per-pixel sum would have it
      continue;
    }
    double& m = mantissa[i & 3];
    m *= split(L);
    // each partial product stays below 2^17: renormalised to [1, 2) every 16 factors < 2.
    if ((i & 63) >= 60) m = split(m);
  }
  const double product = (mantissa[0] * mantissa[1]) * (mantissa[2] * mantissa[3]);
  return std::log(product) + static_cast<double>(exponent) * std::log(2.0) + odd;
}

}  // namespace

Film::Film(const RenderSettings& settings) : settings_(settings), oetf_lut_(kLutSize) {
  for (int i = 0; i < kLutSize; ++i) {
    const double v = static_cast<double>(i) / (kLutSize - 1);
    oetf_lut_[i] = static_cast<uint8_t>(std::lround(std::clamp(LinearToSrgb(v), 0.0, 1.0) * 255.0));
  }
}

double Film::LogAverageLuminance(const ImageF& radiance, ThreadPool* pool) const {
  if (radiance.empty()) return kMinLuminance;
  const int w = radiance.width, h = radiance.height;
  std::vector<double> row_sum(h, 0.0);
  ParallelForOrSerial(pool, h, [&](int v) { row_sum[v] = SumLog(radiance.at(0, v), w); });
  // row order: independent of the thread count
  return LogAverageFromRowSums(row_sum.data(), h, static_cast<int64_t>(w) * h, kMinLuminance);
}

double Film::Ev100(const ImageF& radiance, ThreadPool* pool) const {
  return Ev100FromLogAverage(settings_.auto_exposure ? LogAverageLuminance(radiance, pool)
                                                     : kMinLuminance);
}

double Film::Ev100FromLogAverage(double log_average) const {
  return FilmEv100(exposure_pod(), log_average);
}

FilmExposurePod Film::exposure_pod() const {
  FilmExposurePod p;
  p.auto_exposure = settings_.auto_exposure ? 1 : 0;
  p.ev100 = settings_.ev100;
  p.compensation_ev = settings_.exposure_compensation_ev;
  return p;
}

void Film::Develop(const ImageF& radiance, double ev100, ThreadPool* pool, ImageU8* rgb,
                   const Eigen::Vector3f& wb_gains) const {
  const int w = radiance.width, h = radiance.height;
  if (rgb->width != w || rgb->height != h || rgb->channels != 3) *rgb = ImageU8(w, h, 3);
  const float exposure = static_cast<float>(ExposureFromEv100(ev100));
  const bool balanced = wb_gains != Eigen::Vector3f::Ones();
  const float channel_exposure[3] = {exposure * wb_gains[0], exposure * wb_gains[1],
                                     exposure * wb_gains[2]};
  const bool filmic = settings_.tone_map == RenderSettings::ToneMap::kFilmic;
  const uint8_t* lut = oetf_lut_.data();
  ParallelForOrSerial(pool, h, [&](int v) {
    const float* src = radiance.at(0, v);
    uint8_t* dst = rgb->at(0, v);
    // per chunk: the table indices (SIMD), then the table look-ups.
    constexpr int kChunk = 240;  // a multiple of 3: whole pixels
    int32_t index[kChunk];
    for (int i0 = 0; i0 < 3 * w; i0 += kChunk) {
      const int m = std::min(kChunk, 3 * w - i0);
      if (balanced || filmic) {
        PixelIndices(src + i0, m, channel_exposure, filmic, index);
      } else {
        ClampIndices(src + i0, m, exposure, index);
      }
      for (int i = 0; i < m; ++i) dst[i0 + i] = lut[index[i]];
    }
  });
}

}  // namespace penumbra
