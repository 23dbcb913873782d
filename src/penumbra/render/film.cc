#include "penumbra/render/film.h"

#include <algorithm>
#include <cmath>

namespace penumbra {
namespace {

constexpr int kLutSize = 65536;

inline float Luminance(const float* c) { return 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2]; }

template <typename Fn>
void ForRows(int rows, ThreadPool* pool, const Fn& fn) {
  if (pool) {
    pool->ParallelFor(rows, [&](int64_t r) { fn(static_cast<int>(r)); });
  } else {
    for (int r = 0; r < rows; ++r) fn(r);
  }
}

}  // namespace

double ExposureFromEv100(double ev100) { return 1.0 / (1.2 * std::exp2(ev100)); }

float AcesFilmic(float x) {
  constexpr float a = 2.51f, b = 0.03f, c = 2.43f, d = 0.59f, e = 0.14f;
  x = std::max(x, 0.0f);
  return std::clamp((x * (a * x + b)) / (x * (c * x + d) + e), 0.0f, 1.0f);
}

float SrgbOetf(float linear) {
  const float v = std::clamp(linear, 0.0f, 1.0f);
  return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

Film::Film(const RenderSettings& settings) : settings_(settings), oetf_lut_(kLutSize) {
  for (int i = 0; i < kLutSize; ++i) {
    const double v = static_cast<double>(i) / (kLutSize - 1);
    const double e = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
    oetf_lut_[i] = static_cast<uint8_t>(std::lround(std::clamp(e, 0.0, 1.0) * 255.0));
  }
}

double Film::LogAverageLuminance(const ImageF& radiance, ThreadPool* pool) const {
  if (radiance.empty()) return kMinLuminance;
  const int w = radiance.width, h = radiance.height;
  std::vector<double> row_sum(h, 0.0);
  ForRows(h, pool, [&](int v) {
    double s = 0;
    for (int u = 0; u < w; ++u)
      s += std::log(std::max(static_cast<double>(Luminance(radiance.at(u, v))), kMinLuminance));
    row_sum[v] = s;
  });
  double total = 0;
  for (double s : row_sum) total += s;  // fixed order: independent of the thread count
  return std::exp(total / (static_cast<double>(w) * h));
}

double Film::Ev100(const ImageF& radiance, ThreadPool* pool) const {
  const double base = settings_.auto_exposure
                          ? std::log2(LogAverageLuminance(radiance, pool) / (0.18 * 1.2))
                          : settings_.ev100;
  return base - settings_.exposure_compensation_ev;
}

void Film::Develop(const ImageF& radiance, double ev100, ThreadPool* pool, ImageU8* rgb) const {
  const int w = radiance.width, h = radiance.height;
  if (rgb->width != w || rgb->height != h || rgb->channels != 3) *rgb = ImageU8(w, h, 3);
  const float exposure = static_cast<float>(ExposureFromEv100(ev100));
  const bool filmic = settings_.tone_map == RenderSettings::ToneMap::kFilmic;
  const uint8_t* lut = oetf_lut_.data();
  ForRows(h, pool, [&](int v) {
    const float* src = radiance.at(0, v);
    uint8_t* dst = rgb->at(0, v);
    for (int i = 0; i < 3 * w; ++i) {
      float x = src[i] * exposure;
      x = filmic ? AcesFilmic(x) : std::clamp(x, 0.0f, 1.0f);
      // NaN-safe: !(x > 0) maps to 0.
      const int k = x > 0 ? static_cast<int>(x * (kLutSize - 1) + 0.5f) : 0;
      dst[i] = lut[std::min(k, kLutSize - 1)];
    }
  });
}

}  // namespace penumbra
