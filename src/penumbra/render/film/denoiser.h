#pragma once
// edge-avoiding a-trous wavelet denoiser for path-traced images.
//
// model: Dammertz, Sewtz, Hanika, Lensch, "Edge-avoiding a-trous wavelet transform for fast
// global illumination filtering", HPG 2010: `iterations` passes of the 5x5 B3-spline kernel
// (1/16, 1/4, 3/8, 1/4, 1/16) with holes (step 2^i at pass i), each tap weighted by
// edge-stopping functions of guide buffers. the edge-stopping functions follow Schied et al.,
// "Spatiotemporal variance-guided filtering" (SVGF), HPG 2017, eq. 3-5:
//
//   w_n = max(0, n_p . n_q)^sigma_normal                         (normals)
//   w_z = exp(-|iz_q - iz_p - grad iz_p . (q - p)| /
//             (sigma_depth (0.1 |grad iz_p . (q - p)|_1 + 0.01 iz_p)))       (depth, iz = 1/z)
//   w_l = exp(-|c_p - c_q| / sqrt(3) / (sigma_luminance sqrt(g3x3(var_p)) + eps_l))  (colour)
//
// with iz = 1/z the inverse depth, which is affine in screen space on a plane (so slanted planes
// filter isotropically while depth steps stop the filter; SVGF compares z with its gradient
// instead), grad iz its screen-space gradient (smaller one-sided difference, so that it does
// not straddle edges), c the rgb of the filtered signal (SVGF compares luminance only; the rgb
// distance / sqrt(3) equals the luminance difference for grey noise and also separates
// colours of equal luminance) and var the variance of its luminance, which is
// propagated through the passes (var' = sum w^2 var / (sum w)^2) so that the luminance test
// tightens as the noise falls. the filtered signal is the demodulated irradiance
// radiance / max(albedo, eps_a), remodulated after the last pass, so textures stay sharp and an
// unfiltered pixel comes back exactly.
//
// pixels without a surface (depth 0: sky, background) pass through unchanged and never
// contribute to surface pixels. results are deterministic and independent of thread count.

#include "penumbra/core/image.h"
#include "penumbra/core/thread_pool.h"

namespace penumbra {

/// parameters of the denoiser.
struct DenoiserSettings {
  int iterations = 5;            ///< a-trous passes (>= 1); footprint 1 + 4 (2^iterations - 1) px
  float sigma_luminance = 4.0f;  ///< luminance edge-stopping, in standard deviations (> 0)
  float sigma_normal = 128.0f;   ///< exponent of the normal cosine (>= 0)
  float sigma_depth = 1.0f;      ///< depth edge-stopping tolerance scale (> 0)

  /// @throws ConfigError if a value is out of range.
  void ValidateOrThrow() const;
};

/// guide buffers of one frame; all have the radiance image's width and height.
struct DenoiserGuides {
  /// (H x W x 3) linear albedo of the first visible surface (averaged over the pixel's samples).
  const ImageF* albedo = nullptr;
  /// (H x W x 3) unit shading normal of the first visible surface, world frame; 0 = none.
  const ImageF* normal = nullptr;
  /// (H x W x 1) z-depth in m of the first visible surface; 0 = no surface (passes through).
  const ImageF* depth = nullptr;
  /// (H x W x 1) variance of each pixel's luminance estimate, (cd/m^2)^2 (sample variance
  /// divided by the sample count), or null: then it is estimated from the spatial variance
  /// of the luminance over the 5x5 neighbourhood of the same surface.
  const ImageF* variance = nullptr;
};

/// the filter. immutable, thread-compatible (one Denoise per pool at a time).
class Denoiser {
 public:
  /// @throws ConfigError for bad settings.
  explicit Denoiser(const DenoiserSettings& settings = {});

  /// denoises `radiance` ((H x W x 3) linear, cd/m^2) into `out` (resized; may not alias
  /// `radiance`). rows are spread over `pool` (null: the calling thread only).
  /// @throws Error if a guide is missing or its size does not match.
  void Denoise(const ImageF& radiance, const DenoiserGuides& guides, ThreadPool* pool,
               ImageF* out) const;

  const DenoiserSettings& settings() const { return settings_; }

 private:
  DenoiserSettings settings_;
};

}  // namespace penumbra
