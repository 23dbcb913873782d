#pragma once
// camera sensor settings of one world-file camera (the `sensor:`, `exposure_time_sec`,
// `distortion`, `stereo` and `depth_noise` keys, README "World file reference"): image formation
// after the renderer's radiance image. plain structs with defaults (header-only, so the
// world-file loader can hold them); the world loader checks ranges at load, and
// sensors/camera_imager.h checks them again (ValidateOrThrow) before use.

#include <optional>
#include <string>
#include <string_view>

#include "penumbra/render/white_balance.h"

namespace penumbra {

/// photon transfer model of the image sensor (EMVA Standard 1288, release 3.1, "Standard for
/// characterization of image sensors and cameras", 2010, sec. 2): a pixel collects
/// mu_e = x * full_well_e * base_iso / iso photo-electrons for an exposed value x (x = 1 fills
/// the well at base ISO), shot noise is Poisson(mu_e), read noise adds N(0, read_noise_e^2)
/// electrons, the well clips at full_well_e, and the ADC gives
/// DN = round(e * gain_dn_per_e) with gain_dn_per_e = (2^adc_bits - 1) / full_well_e * iso /
/// base_iso, clipped to [0, 2^adc_bits - 1]. in DN: variance = gain * mean + (gain *
/// read_noise_e)^2 (+ 1/12 from quantisation).
struct ImageNoiseConfig {
  bool enabled = false;
  double full_well_e = 10000;  ///< electrons at saturation, > 0
  double read_noise_e = 3;     ///< read noise standard deviation, electrons, >= 0
  double iso = 100;            ///< sensor gain as ISO speed, > 0
  double base_iso = 100;       ///< ISO at which x = 1 fills the well, > 0
  int adc_bits = 12;           ///< ADC resolution, 1..16
};

/// active depth sensor noise (sensors/depth_noise.h): a preset name and optional overrides.
struct DepthNoiseConfig {
  std::string preset;  ///< "" = noise-free depth; else one of kDepthNoisePresets
  std::optional<double> min_range_m, max_range_m;  ///< override the preset's working range
};

/// names accepted by DepthNoiseConfig::preset.
inline constexpr std::string_view kDepthNoisePresets[] = {"realsense_d435", "kinect_v1",
                                                          "kinect_v2"};

/// everything between the renderer's radiance and the camera's images.
struct CameraSensorConfig {
  double exposure_time_sec = 0.01;  ///< shutter open time T, >= 0
  /// motion blur: sub-frames rendered at times (k + 0.5) T / n, k < n, and averaged; 1 = none.
  int motion_blur_samples = 1;
  /// rolling shutter: row v starts its exposure v * line_time_sec after row 0; 0 = global.
  double rolling_shutter_line_time_sec = 0;
  /// auto-exposure adaptation: EV follows the metered EV as
  /// EV_k = EV_target + (EV_{k-1} - EV_target) exp(-dt / tau); 0 = instant (per-frame metering).
  double auto_exposure_time_constant_sec = 0;
  ImageNoiseConfig noise;
  int jpeg_quality = 0;        ///< 0 = lossless; 1..100 = JPEG round trip at this quality
  bool lens_droplets = true;   ///< water drops on the lens while it rains (EffectsFrame kRain)
  int lens_droplet_count = 6;  ///< drops on the lens while it rains, >= 0
  /// white balance of the rgb image (render/white_balance.h), applied to the linear radiance
  /// before exposure and tone map. default daylight: the scene's sky and sun on a horizontal
  /// surface is the illuminant (a camera's daylight preset for the scene's own daylight), so
  /// neutral materials under it come out neutral; gray world (auto) would instead tint a frame
  /// filled by one coloured object.
  WhiteBalance white_balance;
  DepthNoiseConfig depth_noise;
  /// stereo pair: > 0 makes two cameras "<name>/left" and "<name>/right", the right one
  /// baseline_m along the left optical x axis.
  std::optional<double> stereo_baseline_m;
};

}  // namespace penumbra
