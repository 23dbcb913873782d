#include "penumbra/sensors/camera_profile.h"

namespace penumbra {

std::optional<CameraProfile> FindCameraProfile(std::string_view name) {
  for (const CameraProfileEntry& e : kCameraProfiles)
    if (e.name == name) return e.id;
  return std::nullopt;
}

std::string_view CameraProfileName(CameraProfile p) {
  for (const CameraProfileEntry& e : kCameraProfiles)
    if (e.id == p) return e.name;
  return "ideal";
}

std::string CameraProfileNames() {
  std::string out;
  for (const CameraProfileEntry& e : kCameraProfiles) {
    if (!out.empty()) out += ", ";
    out += e.name;
  }
  return out;
}

double SaturationIso(double full_well_e, double quantum_efficiency, double pixel_pitch_um) {
  // photons of 555 nm per lux s per um^2: (1 / 683 W/m^2) / (h c / 555 nm) / 1e12 um^2/m^2
  constexpr double kPhotonsPerLuxSecUm2 = 4090;
  const double h_sat =
      full_well_e / (quantum_efficiency * pixel_pitch_um * pixel_pitch_um * kPhotonsPerLuxSecUm2);
  return 78.0 / h_sat;
}

CameraSensorConfig CameraProfileConfig(CameraProfile p) {
  CameraSensorConfig c;
  c.profile = p;
  switch (p) {
    case CameraProfile::kIdeal:
      break;
    case CameraProfile::kRealsenseD435Rgb: {
      // OV2740: 1.4 um BSI pixel, RAW10 (datasheet); well, noise and QE estimated
      c.noise.enabled = true;
      c.noise.full_well_e = 4500;
      c.noise.read_noise_e = 2.5;
      c.noise.dark_current_e_per_s = 8;
      c.noise.dsnu_e = 1.0;
      c.noise.prnu = 0.01;
      c.noise.adc_bits = 10;
      c.noise.base_iso = SaturationIso(c.noise.full_well_e, 0.55, 1.4);
      c.noise.iso = c.noise.base_iso;
      // rolling shutter: 1080 rows read within one 30 fps frame (estimate 30 ms)
      c.rolling_shutter_readout_sec = 0.030;
      c.exposure_time_sec = 0.01;
      c.motion_blur_samples = 4;
      c.auto_exposure.enabled = true;
      c.auto_exposure.f_number = 2.0;
      c.auto_exposure.min_exposure_time_sec = 1e-4;      // one librealsense exposure unit
      c.auto_exposure.max_exposure_time_sec = 1.0 / 30;  // auto exposure within the frame time
      c.auto_exposure.max_gain = 8;                      // librealsense gain 128 (estimate 8x)
      c.auto_exposure.motion_blur_step_sec = 0.008;
      c.optics.reference_width = 1920;
      c.optics.vignetting_exponent = 4;  // cos^4: a small wide lens without correction
      c.optics.psf_sigma_px = 0.8;
      c.optics.lateral_ca_px = 1.5;
      break;
    }
    case CameraProfile::kBlackflySImx250: {
      // FLIR EMVA 1288 table of the BFS-U3-51S5 (IMX250), rounded
      c.noise.enabled = true;
      c.noise.full_well_e = 10500;
      c.noise.read_noise_e = 2.3;
      c.noise.dark_current_e_per_s = 3;
      c.noise.dsnu_e = 1.5;
      c.noise.prnu = 0.006;
      c.noise.adc_bits = 12;
      c.noise.base_iso = SaturationIso(c.noise.full_well_e, 0.64, 3.45);
      c.noise.iso = c.noise.base_iso;
      c.exposure_time_sec = 0.01;
      c.motion_blur_samples = 4;
      c.auto_exposure.enabled = true;
      c.auto_exposure.f_number = 2.8;
      c.auto_exposure.min_exposure_time_sec = 6e-6;
      c.auto_exposure.max_exposure_time_sec = 0.030;  // the camera's auto exposure upper limit
      c.auto_exposure.max_gain = 15.85;               // 24 dB auto gain upper limit
      c.auto_exposure.motion_blur_step_sec = 0.008;
      c.optics.reference_width = 2448;
      c.optics.vignetting_exponent = 4;
      c.optics.psf_sigma_px = 0.6;
      c.optics.lateral_ca_px = 0.8;
      break;
    }
  }
  return c;
}

}  // namespace penumbra
