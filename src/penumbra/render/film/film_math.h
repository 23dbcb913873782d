#pragma once
// the film's per-pixel formulas (render/film/film.h: exposure, white-balance gains, the
// hue-preserving ACES filmic map or a clamp, the sRGB encoding table's index), shared by Film
// on the CPU and the CUDA kernels. scalar (float) functions.

#include <cmath>
#include <cstdint>

#include "penumbra/core/host_device.h"
#include "penumbra/render/shading_math.h"

namespace penumbra {

/// entries of the sRGB encoding table (Film): code of i / (kFilmLutSize - 1).
constexpr int kFilmLutSize = 65536;

/// photometric exposure H for an exposure value at ISO 100: 1 / (1.2 2^ev100) (saturation-based
/// speed, Lagarde & de Rousiers, "Moving Frostbite to physically based rendering", 2014, eq. 12).
PB_HOST_DEVICE inline double ExposureFromEv100(double ev100) { return 1.0 / (1.2 * exp2(ev100)); }

/// ACES filmic fit (Narkowicz 2015, "ACES filmic tone mapping curve") of a non-negative exposed
/// value, in [0, 1].
PB_HOST_DEVICE inline float AcesFilmic(float x) {
  constexpr float a = 2.51f, b = 0.03f, c = 2.43f, d = 0.59f, e = 0.14f;
  x = pbm::Max(x, 0.0f);
  return pbm::Clamp((x * (a * x + b)) / (x * (c * x + d) + e), 0.0f, 1.0f);
}

/// hue-preserving filmic map of an exposed linear RGB value x (>= 0; NaN channels stay NaN):
/// y = x AcesFilmic(m) / m, m = max(x), each y in [0, 1]; all 0 when m <= 0 (Naik and Murthy,
/// IEEE Trans. Image Processing 12(12), 2003: max-RGB scaling keeps hue and saturation).
PB_HOST_DEVICE inline void HuePreservingFilmic(const float x[3], float y[3]) {
  // the largest channel; NaN channels never win, so they stay NaN (and encode as 0).
  float m = 0.0f;
  for (int c = 0; c < 3; ++c)
    if (x[c] > m) m = x[c];
  // m = +inf gives NaN (black), as the per-channel curve did.
  const float ratio = m > 0.0f ? AcesFilmic(m) / m : 0.0f;
  for (int c = 0; c < 3; ++c) y[c] = pbm::Clamp(pbm::Max(x[c], 0.0f) * ratio, 0.0f, 1.0f);
}

/// index into the encoding table of a tone-mapped value x in [0, 1]: round(x (size - 1));
/// NaN-safe (!(x > 0) maps to 0).
PB_HOST_DEVICE inline int32_t FilmLutIndex(float x) {
  const int32_t k = x > 0 ? static_cast<int32_t>(x * (kFilmLutSize - 1) + 0.5f) : 0;
  return k < kFilmLutSize - 1 ? k : kFilmLutSize - 1;
}

/// the encoding-table indices of one pixel of linear radiance rgb: each channel times its
/// exposure (exposure x white-balance gain), then the hue-preserving filmic map (filmic) or a
/// clamp to [0, 1] per channel.
PB_HOST_DEVICE inline void DevelopPixelIndices(const float rgb[3], const float exposure[3],
                                               bool filmic, int32_t index[3]) {
  const float x[3] = {rgb[0] * exposure[0], rgb[1] * exposure[1], rgb[2] * exposure[2]};
  if (filmic) {
    float y[3];
    HuePreservingFilmic(x, y);
    for (int c = 0; c < 3; ++c) index[c] = FilmLutIndex(y[c]);
  } else {
    for (int c = 0; c < 3; ++c) index[c] = FilmLutIndex(pbm::Clamp(x[c], 0.0f, 1.0f));
  }
}

/// pixels darker than this (cd/m^2) count as this in the log-average (keeps black pixels from
/// driving the exposure to infinity).
constexpr double kMinLuminance = 1e-4;

/// ln(max(L, min_luminance)) of a pixel's Rec. 709 luminance L (the log-average's term).
PB_HOST_DEVICE inline double LogLuminanceTerm(const float rgb[3], double min_luminance) {
  const double L = static_cast<double>(pbm::Luminance709(rgb[0], rgb[1], rgb[2]));
  return log(L < min_luminance ? min_luminance : L);
}

/// the exposure settings of a film (RenderSettings: auto_exposure, ev100,
/// exposure_compensation_ev) as plain data, for FilmEv100 on either processor.
struct FilmExposurePod {
  int32_t auto_exposure = 1;   ///< 1: from the image's log-average luminance; 0: manual
  double ev100 = 10;           ///< the manual EV100
  double compensation_ev = 0;  ///< stops subtracted from the (auto or manual) EV100
};

/// the log-average luminance exp(total / pixels) of an image of `pixels` pixels whose
/// `count` rows' log-luminance sums (LogLuminanceTerm over each row) are rows[0 .. count),
/// added in row order (so the result does not depend on how the rows were summed in
/// parallel); `min_luminance` when pixels <= 0.
PB_HOST_DEVICE inline double LogAverageFromRowSums(const double* rows, int count, int64_t pixels,
                                                   double min_luminance) {
  double total = 0;
  for (int v = 0; v < count; ++v) total += rows[v];
  return pixels > 0 ? exp(total / static_cast<double>(pixels)) : min_luminance;
}

/// the EV100 of an image whose log-average luminance is `log_average` (cd/m^2; render/film/film.h):
/// auto, log2(L_avg / (0.18 x 1.2)) (the key 0.18, Reinhard et al. 2002), else the manual
/// EV100; minus the compensation.
PB_HOST_DEVICE inline double FilmEv100(const FilmExposurePod& film, double log_average) {
  const double base = film.auto_exposure != 0 ? log2(log_average / (0.18 * 1.2)) : film.ev100;
  return base - film.compensation_ev;
}

/// a frame's EV100 from its rows' log-luminance sums (LogAverageFromRowSums, FilmEv100), and
/// the per-channel exposures of DevelopPixelIndices: float(ExposureFromEv100) times each
/// white-balance gain (as Film::Develop). the CUDA backend's auto exposure, on the host and
/// on the device (the device's exp, log2 and exp2 in double need not round as the host's C
/// library does; its caller checks the device's result against the host's).
PB_HOST_DEVICE inline double FrameExposure(const FilmExposurePod& film, const double* rows,
                                           int count, int64_t pixels, double min_luminance,
                                           const float white_balance_gains[3], float exposure[3]) {
  const double ev100 = FilmEv100(film, LogAverageFromRowSums(rows, count, pixels, min_luminance));
  const float e = static_cast<float>(ExposureFromEv100(ev100));
  for (int c = 0; c < 3; ++c) exposure[c] = e * white_balance_gains[c];
  return ev100;
}

}  // namespace penumbra
