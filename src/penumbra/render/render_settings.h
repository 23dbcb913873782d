#pragma once
// settings that pick the render quality tier and the exposure / tone mapping.

#include <cstdint>
#include <string>

namespace penumbra {

/// render quality and image formation. both tiers share one code path (scene,
/// materials, lights, camera); they differ in the light transport they simulate.
struct RenderSettings {
  /// the ray-tracing backend: MakeRenderer and MakeRayQuery (render/backends/) build
  /// its Renderer and RayQuery.
  enum class Backend {
    kEmbree,  ///< Embree 3 on the CPU (render/cpu/, render/embree/); world key `cpu`, `embree`
    kCuda,    ///< the CUDA backend on an NVIDIA GPU (render/cuda/, docs/gpu.md); world key `cuda`
    kAuto,    ///< kCuda when a CUDA device is present (one log line says so), else kEmbree
  };
  Backend backend = Backend::kAuto;
  enum class Tier {
    kRealtime,    ///< direct lighting with ray-traced (hard or soft) shadows + sky ambient, 1
                  ///< sample/pixel
    kPathtraced,  ///< unidirectional path tracing, NEE with MIS, N samples/pixel, denoised
  };
  Tier tier = Tier::kRealtime;
  int samples_per_pixel = 16;  ///< pathtraced: samples per pixel (>= 1)
  int max_bounces = 4;         ///< pathtraced: maximum path length in bounces (>= 1)
  bool denoise = true;         ///< pathtraced: edge-aware denoiser guided by albedo/normal/depth
  int threads = 0;             ///< render threads; 0 = all hardware threads
  bool auto_exposure = true;   ///< per-frame exposure from the image's log-average luminance
  double ev100 = 10;           ///< manual exposure value at ISO 100
  double exposure_compensation_ev = 0;  ///< added to the (auto or manual) exposure, in stops
  enum class ToneMap { kFilmic, kLinear };
  ToneMap tone_map = ToneMap::kFilmic;  ///< filmic: ACES fit (Narkowicz 2015); linear: clamp
  uint64_t seed = 0;  ///< world seed; per-pixel randomness = f(seed, frame, pixel, sample)
  /// most trilinear taps of an anisotropic texture lookup (render/material/material_eval.h,
  /// "filtering"); 1 = isotropic trilinear filtering. both tiers.
  int max_anisotropy = 16;

  /// valid ranges (inclusive), checked by ValidateOrThrow and by the world-file loader
  /// (which links without the renderer).
  static constexpr int kMaxSamplesPerPixel = 65536;
  static constexpr int kMaxBounces = 64;
  static constexpr int kMaxThreads = 256;
  static constexpr int kMaxAnisotropy = 64;
  static constexpr double kMinEv100 = -10, kMaxEv100 = 30;
  static constexpr double kMaxCompensationEv = 20;  ///< |exposure_compensation_ev| <= this

  /// throws ConfigError if a value is out of range.
  void ValidateOrThrow() const;

  /// the backend a world's `render.backend` or a `--backend` flag names: cpu (or embree), cuda
  /// or auto. @throws ConfigError (key "render.backend") for any other name.
  static Backend BackendFromName(const std::string& name);
};

}  // namespace penumbra
