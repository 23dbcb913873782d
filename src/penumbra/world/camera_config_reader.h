#pragma once
// world-file keys of camera sensors and semantic classes (README "World file reference"):
//
//   cameras[i]:
//     profile: ideal                       a named camera (sensors/camera_profile.h); the keys
//                                           below override its values; absent = ideal
//     distortion: {k1, k2, p1, p2, k3}     Brown-Conrady, OpenCV names; rejected if it folds
//                                           the image (render/camera/camera_distortion.h)
//     exposure_time_sec: 0.01              shutter time T (>= 0)
//     motion_blur_samples: 1               sub-frames over T (1..64)
//     rolling_shutter_line_time_sec: 0     per-row readout delay (>= 0; 0 = global shutter)
//     auto_exposure_time_constant_sec: 0   EV adaptation time constant (>= 0; 0 = instant)
//     noise: {full_well_e, read_noise_e, iso, base_iso, adc_bits, dark_current_e_per_s, dsnu_e,
//             prnu}                        present = enabled
//     optics: {vignetting_exponent, psf_sigma_px, lateral_ca_px, reference_width}
//     auto_exposure: {enabled, f_number, min_exposure_time_sec, max_exposure_time_sec, max_gain,
//                     saturated_fraction, max_highlight_reduction_ev, motion_blur_step_sec}
//     jpeg_quality: 0                      0 = lossless PNG; 1..100 JPEG round trip
//     lens_droplets: {enabled, count}      drops on the lens while it rains (default on, 6)
//     depth_noise: {preset, min_range_m, max_range_m}   realsense_d435 | kinect_v1 | kinect_v2
//     stereo: {baseline_m}                 two cameras <name>/left and <name>/right
//   semantic_classes:
//     - {name: robot, id: 1, bodies: ["rover/*"], geoms: [...], materials: [...]}

#include <vector>

#include "penumbra/config/param_reader.h"
#include "penumbra/world/world_config.h"

namespace penumbra {

/// the camera keys handled here (for the caller's ExpectMap list).
const std::vector<std::string_view>& CameraSensorKeys();

/// reads a `profile` value. @throws ConfigError naming the key and listing the profile names
/// when it names none (`who` prefixes the message, e.g. "camera 'front': ").
CameraProfile ReadCameraProfile(const ParamReader& r, const std::string& who);

/// reads the sensor keys of camera entry `r` into `c` (after width/height/fovy/intrinsics) and
/// checks them, including that the distortion does not fold the image (when the field of view is
/// known at load; MJCF camera overrides without one are checked at scene assembly). `stereo` is
/// rejected for MJCF camera overrides.
/// @throws ConfigError naming the file, line, key path and the camera.
void ReadCameraSensorKeys(const ParamReader& r, CameraConfig* c);

/// reads the `semantic_classes:` list. @throws ConfigError for bad ids, duplicate names/ids.
std::vector<SemanticClassConfig> ReadSemanticClasses(const ParamReader& r);

}  // namespace penumbra
