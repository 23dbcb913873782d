#pragma once
// image formation: exposure, tone mapping and sRGB encoding of a linear radiance image.
//
//   exposure  H = 1 / (1.2 2^EV100)  (saturation-based speed, Lagarde & de Rousiers, "Moving
//             Frostbite to physically based rendering", SIGGRAPH 2014 course, eq. 12), so a
//             pixel value is radiance x H.
//   auto EV   the log-average luminance L_avg = exp(mean(log(max(L, kMinLuminance)))) is mapped
//             to the key 0.18 (Reinhard et al., "Photographic tone reproduction", 2002):
//             H = 0.18 / L_avg, i.e. EV100 = log2(L_avg / (0.18 x 1.2)).
//   compensation  +c stops brighten the image: the EV100 used is EV100 - c.
//   tone map  filmic: the ACES filmic fit of Narkowicz 2015 ("ACES filmic tone mapping
//             curve"), without his 0.6 pre-scale, applied to the largest channel m of the exposed
//             linear RGB, and all three channels scaled by AcesFilmic(m) / m. scaling keeps the
//             ratios of the channels, hence the hue (and saturation) of every pixel, and the
//             result never leaves [0, 1]^3: the hue-preserving "max-RGB" scaling of Naik and
//             Murthy ("Hue-preserving color image enhancement without gamut problem", IEEE
//             Trans. Image Processing 12(12), 2003). a per-channel curve compresses the largest
//             channel most, so bright saturated colours drift towards the nearest secondary
//             (orange to yellow, blue to cyan) and wash out. grey pixels get exactly the
//             per-channel curve. linear: clamp to [0, 1], per channel.
//   white balance  optional per-channel gains on the linear radiance, before the exposure and
//             the tone map (render/film/white_balance.h); the max-RGB filmic map then keeps their
//             hue and saturation.
//   encoding  sRGB OETF (IEC 61966-2-1) to 8 bits through a 65536-entry table (within 1 code
//             value of the exact rounding).
// luminance uses the Rec. 709 weights (0.2126, 0.7152, 0.0722). all sums run in a fixed order,
// so results do not depend on the thread count.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "penumbra/core/image.h"
#include "penumbra/core/thread_pool.h"
#include "penumbra/render/film/film_math.h"
#include "penumbra/render/render_settings.h"

namespace penumbra {

// kMinLuminance: render/film_math.h.

// ExposureFromEv100, AcesFilmic and HuePreservingFilmic: render/film/film_math.h (shared with the
// CUDA backend); the sRGB encoding of the table: LinearToSrgb, core/srgb.h.

/// turns radiance images into display images. immutable, thread-compatible.
class Film {
 public:
  /// keeps the exposure / tone-mapping fields of `settings`.
  explicit Film(const RenderSettings& settings);

  /// log-average luminance of a (H x W x 3) radiance image (cd/m^2); kMinLuminance if empty.
  double LogAverageLuminance(const ImageF& radiance, ThreadPool* pool) const;

  /// the EV100 used for `radiance`: auto (from its log-average luminance) or manual, minus
  /// the exposure compensation.
  double Ev100(const ImageF& radiance, ThreadPool* pool) const;

  /// the EV100 used for an image whose log-average luminance is `log_average` (cd/m^2): as
  /// Ev100, for a log-average computed elsewhere (the CUDA backend's).
  double Ev100FromLogAverage(double log_average) const;
  /// the exposure settings (auto or manual EV100, compensation) as plain data: film_math.h's
  /// FilmEv100 of them is Ev100FromLogAverage.
  FilmExposurePod exposure_pod() const;

  /// the sRGB encoding table (kFilmLutSize 8-bit codes of i / (kFilmLutSize - 1)).
  const std::vector<uint8_t>& oetf_lut() const { return oetf_lut_; }
  /// the tone map is the hue-preserving filmic map (else a clamp).
  bool filmic() const { return settings_.tone_map == RenderSettings::ToneMap::kFilmic; }

  /// exposes `radiance` ((H x W x 3) cd/m^2) with EV100 `ev100`, tone maps and encodes it
  /// into `rgb` ((H x W x 3) uint8 sRGB, resized). rows are spread over `pool` (may be null).
  /// `wb_gains` (white balance, render/film/white_balance.h) multiply the channels of the linear
  /// radiance before the exposure and the tone map; unit gains leave the image as it was.
  void Develop(const ImageF& radiance, double ev100, ThreadPool* pool, ImageU8* rgb,
               const Eigen::Vector3f& wb_gains = Eigen::Vector3f::Ones()) const;

 private:
  RenderSettings settings_;
  std::vector<uint8_t> oetf_lut_;  // sRGB 8-bit code of i / (size - 1)
};

}  // namespace penumbra
