#pragma once
// camera sensor settings of one world-file camera (the `sensor:`, `exposure_time_sec`,
// `distortion`, `stereo` and `depth_noise` keys, README "World file reference"): image formation
// after the renderer's radiance image. plain structs with defaults (header-only, so the
// world-file loader can hold them); the world loader checks ranges at load, and
// sensors/camera_imager.h checks them again (ValidateOrThrow) before use.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "penumbra/render/film/white_balance.h"

namespace penumbra {

/// the named camera profiles (sensors/camera_profile.h has their values and sources).
enum class CameraProfile : uint8_t {
  kIdeal,             ///< "ideal": the renderer's clean image (every field at its default)
  kRealsenseD435Rgb,  ///< "realsense_d435_rgb": the D435's OV2740 colour imager
  kBlackflySImx250,   ///< "blackfly_s_imx250": a global-shutter Sony Pregius machine-vision camera
};

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
  /// dark current: a mean of dark_current_e_per_s * T electrons (T the exposure time) is added
  /// to every pixel before the shot noise, so it is Poisson too (EMVA 1288 sec. 2.3), >= 0.
  double dark_current_e_per_s = 0;
  /// fixed pattern noise: dark signal non-uniformity, the standard deviation over pixels of a
  /// fixed per-pixel offset, electrons, >= 0 (EMVA 1288 sec. 8, DSNU1288).
  double dsnu_e = 0;
  /// photo response non-uniformity: the standard deviation over pixels of a fixed per-pixel
  /// gain, as a fraction of the signal, in [0, 0.5] (EMVA 1288 sec. 8, PRNU1288).
  double prnu = 0;
};

/// optics between the scene and the sensor, applied to the radiance before the exposure.
/// lengths in pixels refer to an image `reference_width` pixels wide (the sensor's native
/// width) and are scaled by width / reference_width for the camera's own width.
struct OpticsConfig {
  /// relative illumination cos^n(theta) of the field angle theta of each pixel (n = 4 is the
  /// natural cos^4 law of a thin lens); 0 = no vignetting. in [0, 8].
  double vignetting_exponent = 0;
  /// standard deviation of a Gaussian lens point spread function, px; 0 = sharp. in [0, 20].
  double psf_sigma_px = 0;
  /// lateral chromatic aberration: the red image is magnified and the blue one shrunk, each by
  /// this many px at the image corner, relative to green; 0 = none. in [0, 20].
  double lateral_ca_px = 0;
  int reference_width = 0;  ///< px the lengths refer to; 0 = the camera's width
};

/// exposure control of a real camera (on when `enabled`): the renderer's auto or manual EV
/// (render/film/film.h) is the target, met by a shutter time in [min, max]_exposure_time_sec and an
/// analog gain in [1, max_gain] at the lens's f-number and the sensor's base ISO
/// (ImageNoiseConfig::base_iso): exposure H = T g base_iso / (100 1.2 N^2) per cd/m^2. past
/// the limits the image is darker than the target. the film's tone curve is then a highlight
/// roll-off over the sensor's range: the raw full scale (full well or the ADC's top code) maps
/// to display white, so highlights compress towards it instead of clipping early, and only
/// pixels whose raw value saturates reach 255. each frame is metered on a quarter-size view of
/// its own capture instant (sensors/camera_imager.h).
struct AutoExposureConfig {
  bool enabled = false;
  double f_number = 2.0;                 ///< lens aperture N, > 0
  double min_exposure_time_sec = 1e-5;   ///< shortest shutter time, > 0
  double max_exposure_time_sec = 0.033;  ///< longest shutter time, >= min
  double max_gain = 1;                   ///< largest analog gain, >= 1 (ISO = base_iso gain)
  /// highlight protection: the exposure is lowered until at most this fraction of pixels
  /// has its largest channel above 80 % of raw full scale (so their noise rarely saturates), by
  /// at most
  /// max_highlight_reduction_ev below the target. in [0, 1]; 1 = off.
  double saturated_fraction = 0.005;
  double max_highlight_reduction_ev = 2;  ///< in [0, 10]
  /// motion blur sub-frames from the exposure time T: ceil(T / step) of them, at most
  /// motion_blur_samples; 0 = always motion_blur_samples. >= 0.
  double motion_blur_step_sec = 0;
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
  /// the named profile these values started from (sensors/camera_profile.h; explicit world-file
  /// keys override its values): for messages only, every behaviour comes from the fields below.
  CameraProfile profile = CameraProfile::kIdeal;
  /// shutter open time T, >= 0 (with auto_exposure enabled: the metering view's, for particle
  /// streaks; the frame's own is metered)
  double exposure_time_sec = 0.01;
  /// motion blur: sub-frames rendered at times (k + 0.5) T / n, k < n, and averaged; 1 = none.
  int motion_blur_samples = 1;
  /// rolling shutter: row v starts its exposure v * line_time_sec after row 0; 0 = global.
  double rolling_shutter_line_time_sec = 0;
  /// rolling shutter given as the sensor's readout time of a whole frame: when
  /// rolling_shutter_line_time_sec is 0, rows are readout / height apart. >= 0.
  double rolling_shutter_readout_sec = 0;
  /// auto-exposure adaptation: EV follows the metered EV as
  /// EV_k = EV_target + (EV_{k-1} - EV_target) exp(-dt / tau); 0 = instant (per-frame metering).
  double auto_exposure_time_constant_sec = 0;
  ImageNoiseConfig noise;
  OpticsConfig optics;
  AutoExposureConfig auto_exposure;
  int jpeg_quality = 0;        ///< 0 = lossless; 1..100 = JPEG round trip at this quality
  bool lens_droplets = true;   ///< water drops on the lens while it rains (EffectsFrame kRain)
  int lens_droplet_count = 6;  ///< drops on the lens while it rains, >= 0
  /// white balance of the rgb image (render/film/white_balance.h), applied to the linear radiance
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
