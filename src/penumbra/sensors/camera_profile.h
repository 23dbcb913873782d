#pragma once
// named camera profiles (the world file's `cameras[i].profile`): the values of
// CameraSensorConfig (sensors/camera_sensor_config.h) that make a camera behave as a real one.
// the set is closed: CameraProfile (camera_sensor_config.h) lists them, kCameraProfiles below
// holds one row per value. explicit world-file keys override a profile's values.
//
//   ideal               the renderer's clean image: every CameraSensorConfig field at its
//                       default (no noise, no optics, the film's EV and tone curve).
//   realsense_d435_rgb  the colour imager of an Intel RealSense D435: OmniVision OV2740,
//                       1920 x 1080, 1.4 um pixels, RAW10, rolling shutter, f/2.0, 69 x 42 deg.
//                       sources: "Intel RealSense Product Family D400 Series Datasheet",
//                       document 337029 (RGB sensor properties: sensor, resolution, RAW10, f/2.0,
//                       FOV, rolling shutter); OmniVision "OV2740 product brief" (1.4 um
//                       OmniBSI-2 pixel); librealsense's RGB controls (exposure 1..10000 x 100
//                       us, auto exposure within the frame time, gain 0..128). OmniVision
//                       publishes no EMVA 1288 report for the OV2740: its full well, read noise,
//                       QE, dark current, DSNU, PRNU, readout time, lens PSF and lateral
//                       chromatic aberration here are estimates for a 1.4 um BSI pixel and a
//                       small f/2.0 lens (docs/cameras.md, "Camera profiles", says which).
//   blackfly_s_imx250   a global-shutter machine-vision camera: Teledyne FLIR Blackfly S
//                       BFS-U3-51S5C (Sony IMX250 Pregius, 2448 x 2048, 3.45 um pixels, 12-bit
//                       ADC). sources: Teledyne FLIR, "Blackfly S USB3 BFS-U3-51S5 imaging
//                       performance (EMVA 1288)" (quantum efficiency, temporal dark noise,
//                       saturation capacity, 12-bit ADC), Sony "IMX250LQR" flyer (pixel size,
//                       global shutter); DSNU, PRNU and dark current as typical Pregius values
//                       (Basler ace acA2440-20gm EMVA 1288 report, IMX264, the same pixel). the
//                       lens (not part of the camera) is taken as an f/2.8 C-mount lens.
//
// the base ISO of a sensor (ImageNoiseConfig::base_iso) is its saturation-based speed (ISO
// 12232: S = 78 / H_sat, H_sat the focal-plane exposure in lux s that fills the well): at
// 555 nm a lux is 4.09e3 photons / (s um^2), so H_sat = full_well / (QE pitch^2 4.09e3)
// (SaturationIso).

#include <optional>
#include <string>
#include <string_view>

#include "penumbra/sensors/camera_sensor_config.h"

namespace penumbra {

/// one named profile: its world-file name and its values.
struct CameraProfileEntry {
  CameraProfile id;
  std::string_view name;  ///< the world-file `profile` value
  /// the sensor's native width in pixels (optics lengths refer to it) and its field of view
  /// (deg) as its maker gives them; 0 for ideal. the world's width, height and fovy are kept:
  /// a profile sets what the camera does to light, not the image size.
  int native_width = 0, native_height = 0;
  double native_hfov_deg = 0, native_vfov_deg = 0;
};

/// every profile, in CameraProfile order.
inline constexpr CameraProfileEntry kCameraProfiles[] = {
    {CameraProfile::kIdeal, "ideal"},
    {CameraProfile::kRealsenseD435Rgb, "realsense_d435_rgb", 1920, 1080, 69, 42},
    {CameraProfile::kBlackflySImx250, "blackfly_s_imx250", 2448, 2048, 0, 0},
};

/// the profile named `name`, or nullopt when there is none.
std::optional<CameraProfile> FindCameraProfile(std::string_view name);

/// the world-file name of `p`.
std::string_view CameraProfileName(CameraProfile p);

/// "ideal, realsense_d435_rgb, blackfly_s_imx250": the names, for error messages.
std::string CameraProfileNames();

/// the sensor settings of profile `p` (ideal: a default CameraSensorConfig).
CameraSensorConfig CameraProfileConfig(CameraProfile p);

/// ISO 12232 saturation-based speed of a pixel: 78 / H_sat with H_sat = full_well_e /
/// (quantum_efficiency pixel_pitch_um^2 4090) lux s (photons of 555 nm). all arguments > 0.
double SaturationIso(double full_well_e, double quantum_efficiency, double pixel_pitch_um);

}  // namespace penumbra
