#pragma once
// active depth camera (RGB-D) noise: turns an exact z-depth image into what an active-stereo,
// structured-light or time-of-flight sensor reports. three families (DepthNoiseModel::Kind):
//
// correlation matchers (realsense_d435: active stereo; kinect_v1: structured light, the
// projector is the second "view"). depth exists only where a block matcher finds its match, and
// that is decided per matching window, never per pixel, so holes are contiguous:
//   1. geometry: z outside [min_range_m, max_range_m], incidence above max_incidence_deg,
//      mirror-like surfaces (reflectance < 0), round-trip transmittance T^2 below
//      min_round_trip_transmittance -> no return.
//   2. the left invalid band (stereo only): the left imager is the reference; a point at depth z
//      seen at column u lands at u - d in the right imager, d = fx b / z (disparity). columns
//      with u - d < 0 are outside the right imager: the band is fx b / z pixels wide (Intel
//      RealSense D400 Series Product Family Datasheet, sec. "Invalid Depth Band":
//      band = HRES B / (2 Z tan(HFOV / 2)) = B F / Z pixels).
//   3. occlusion: a pixel whose right-imager (or projector) position u - d is covered by a
//      closer point to its right (u2 > u with u2 - d2 <= u - d) is seen by one view only: the
//      shadow left of every foreground edge, d_fg - d_bg pixels wide.
//   4. texture: the IR image the matcher sees, in units of the projector's dot irradiance on a
//      white wall at 1 m: I = A + S dots + V with
//        S = rho cos(theta) T^2 / z^2  (projector dots: inverse-square, reflectance, incidence,
//                                       round-trip transmittance T^2 through fog or smoke),
//        A = L / projector_luminance_1m (ambient: the scene's luminance L in cd/m^2 from the
//            rendered image, times ambient_fraction; without an image default_ambient_cd_m2
//            rho T; sunlight makes A large and washes the dots out),
//        V = backscatter (1 - T^2)      (projector light scattered back by the medium: a veil
//                                       that adds shot noise and no texture).
//      over the matching window (window_px square) the texture is the standard deviation
//      sqrt(var_window(A) + dot_fill (1 - dot_fill) mean_window(S)^2) (passive texture only
//      for stereo: kinect_v1 sees only its own pattern through its band-pass filter), the mean
//      is m = mean_window(A) + dot_fill mean_window(S) + V. the imager's exposure is global:
//      g = target_electrons / max(frame mean of m, min_frame_signal) electrons per unit (the
//      auto exposure at its limit in the dark). the window's signal-to-noise ratio is
//      SNR = g texture / sqrt(g m + read_noise_e^2).
//   5. the matcher's score fluctuates from window to window: SNR is multiplied by
//      exp(snr_jitter G), G a unit-variance Gaussian field smoothed over the window (white noise
//      box-filtered at window_px and rescaled), so near the threshold holes come as blobs of the
//      window's size. a window matches when that SNR >= min_snr; a pixel keeps its depth when
//      more than half of the windows around it (window_px square) matched (the matcher's
//      consistency filtering: no isolated single-pixel holes or islands).
//   6. depth error: axial N(0, sigma_z^2) with sigma_z = z^2 subpixel / (fx b) (stereo; Intel,
//      "Tuning depth cameras for best performance", Grunnet-Jepsen, Sweetser, Woodfill, rev.
//      2.0: depth RMS error = z^2 subpixel / (f b), subpixel 0.08 typical) or Nguyen et al.
//      (kinect_v1); lateral: the depth is read from a pixel displaced by N(0, sigma_L^2).
//
// time of flight (kinect_v2): every pixel measures its own phase, so holes are per pixel:
//   1. geometry as above, reflectance below min_reflectance -> no return; in media the return
//      survives with probability T^2 and never below min_round_trip_transmittance.
//   2. mixed ("flying") pixels: a pixel integrates the returns of its footprint, a Gaussian
//      point spread of tof_psf_sigma_px over its 3 x 3 neighbours; each neighbour adds the
//      phasor a exp(i 4 pi f r / c) with amplitude a = psf rho cos(theta) / r^2 at its range r.
//      on a depth edge the phase of the sum lies between foreground and background (a point
//      floating between them); on a continuous surface it is the pixel's own range.
//   3. multipath: light from the emitter at the camera bounces off one surface onto another
//      before returning: screen-space one-bounce interreflection between patches of the depth
//      image (a grid of at most 48 x 36 patches; patch q lit by E_q = cos(theta_q) / r_q^2
//      reflects rho_q E_q / pi to patch p with the form factor cos_q cos_p dA_q / d^2; both must
//      face each other; visibility between patches is not tested). the indirect phasors (path
//      r_q + d + r_p) join the direct one (2 r_p), so concave corners read long; a flat wall
//      has no interreflection and no bias. the bias is bilinearly spread from the patch grid.
//   4. axial (Fankhauser et al.) and lateral noise as above.
//
// presets (DepthNoisePreset):
//   realsense_d435  active stereo, baseline 50 mm (datasheet), subpixel 0.08 (Tuning white
//                   paper), range 0.2-10 m; projector: ~5000 dots over 86 x 57 deg (Intel,
//                   "Projectors for D400 Series Depth Cameras", Grunnet-Jepsen et al., rev.
//                   1.0), 360 mW average and 4.25 W peak optical power, pulsed with the
//                   exposure (D435 module manual): dot_fill 0.1 (each dot ~3 x 3 px at
//                   848 x 480) and projector_luminance_1m = 1800 cd/m^2: 4.25 W over 1.33 sr
//                   is 3.2 W/m^2 at 1 m, 32 W/m^2 inside the dots, ~19 W/m^2 after silicon's
//                   lower quantum efficiency at 850 nm (0.6 of visible), the irradiance of
//                   ~5800 lux of white light, whose luminance on a white wall is 1800 cd/m^2
//                   (our estimate; the D435 imagers have no IR-cut filter and see visible and
//                   near-infrared light alike: ambient_fraction 1). matcher: window 7 px,
//                   target_electrons 2000, read noise 5 e-, min_snr 1, snr_jitter 0.35,
//                   backscatter 0.5, min_frame_signal 0.05 (our choices). validated
//                   (tests/sensors/depth_noise_test.cc) against the datasheet's active-stereo
//                   depth quality (textureless white wall, 80 % ROI: fill rate >= 99 %, RMS
//                   error <= 2 % at 2 m), the Tuning paper's RMS error, and the Projectors
//                   paper (passive texture works outdoors, sunlight washes the projector out of
//                   a textureless wall).
//   kinect_v1       structured light; Nguyen, Izadi, Lovell, "Modeling Kinect sensor noise for
//                   improved 3D reconstruction and tracking", 3DIMPVT 2012, eqs. (1)-(3):
//                   sigma_z = 0.0012 + 0.0019 (z - 0.4)^2 + 0.0001 / sqrt(z) theta^2 / (pi/2 -
//                   theta)^2 m, sigma_L = 0.8 + 0.035 theta / (pi/2 - theta) px; range 0.5-4.0
//                   m; projector-camera baseline 75 mm; continuous 830 nm projector behind a
//                   band-pass filter: projector_luminance_1m 80 cd/m^2 and ambient_fraction
//                   0.04 (sunlight's share in a 20 nm band; our estimates), no passive
//                   texture, no invalid band (the projector's field covers the camera's),
//                   window 9 px (our choice).
//   kinect_v2       time of flight; Fankhauser et al., "Kinect v2 for mobile robot navigation:
//                   evaluation and modeling", ICAR 2015: sigma_z = 1.5 - 0.5 z + 0.3 z^2 +
//                   0.1 z^1.5 theta^2 / (pi/2 - theta)^2 mm, lateral sigma_L = 1.6 px; range
//                   0.5-4.5 m (Microsoft spec); mixed and multipath returns are combined at
//                   16 MHz, the lowest of its modulation frequencies (unambiguous range 9.4 m;
//                   the unwrapping across its three frequencies is not modelled),
//                   tof_psf_sigma_px 0.5 (our choice).
// all presets drop returns above 80 deg incidence and on specular (metallic > 0.5 and roughness
// < 0.2) surfaces; min_round_trip_transmittance = 0.05.
// random numbers: Rng(HashKeys(key, pixel, stream)), so output is a pure function of the inputs
// (not of the thread count).

#include <cstdint>
#include <string>

#include "penumbra/core/image.h"
#include "penumbra/core/thread_pool.h"
#include "penumbra/render/camera/camera.h"
#include "penumbra/scene/effects_frame.h"
#include "penumbra/sensors/camera_sensor_config.h"

namespace penumbra {

/// parameters of one depth sensor (see the file comment for the presets and their sources).
struct DepthNoiseModel {
  enum class Axial { kKinectV1, kKinectV2, kStereoRms };
  /// how returns are lost: a window-based correlation matcher (stereo, structured light) or
  /// per-pixel time of flight with mixed pixels and multipath.
  enum class Kind { kActiveStereo, kStructuredLight, kTimeOfFlight };
  std::string name;
  Kind kind = Kind::kActiveStereo;
  Axial axial = Axial::kStereoRms;
  double min_range_m = 0.2, max_range_m = 10;
  double lateral_sigma_px = 0.5;     ///< constant part of sigma_L
  double lateral_theta_coeff = 0.0;  ///< sigma_L += coeff theta / (pi/2 - theta)
  double stereo_subpixel = 0.08;     ///< kStereoRms: disparity RMS error, px
  double stereo_baseline_m = 0.05;   ///< stereo / projector-camera baseline along optical +x, m
  double max_incidence_deg = 80;     ///< larger incidence angles give no return
  double min_reflectance = 0.05;     ///< kTimeOfFlight: darker surfaces give no return
  double min_round_trip_transmittance = 0.05;  ///< below: no return in smoke / fog

  // correlation matchers (kActiveStereo, kStructuredLight)
  int window_px = 7;                     ///< matching window side, px (odd)
  double projector_luminance_1m = 1800;  ///< dot irradiance on a white wall at 1 m, cd/m^2 equiv.
  double dot_fill = 0.1;                 ///< fraction of the image the dots cover
  double ambient_fraction = 1.0;         ///< share of the scene luminance the imagers see
  bool passive_texture = true;           ///< the scene's own texture helps the matcher
  bool invalid_band = true;              ///< left band outside the second view (stereo)
  double target_electrons = 2000;        ///< auto exposure's mean signal, e-
  double read_noise_e = 5;               ///< imager read noise, e-
  double min_frame_signal = 0.05;        ///< exposure limit: darker frames get no more gain
  double min_snr = 1.0;                  ///< window SNR below this: no match
  double snr_jitter = 0.35;              ///< log-normal spread of the window score
  double backscatter = 0.5;              ///< veil per unit (1 - T^2), projector units
  double default_ambient_cd_m2 = 30;     ///< scene luminance of a white surface w/o image

  // time of flight (kTimeOfFlight)
  double tof_psf_sigma_px = 0.5;  ///< pixel footprint (Gaussian sigma), px
  double modulation_hz = 16e6;    ///< phase of mixed and multipath returns
  bool multipath = true;          ///< one-bounce interreflection bias

  /// axial standard deviation sigma_z in m at z-depth z (m), incidence angle theta (rad), for a
  /// depth image with focal length fx_px.
  double AxialSigma(double z, double theta, double fx_px) const;
  /// lateral standard deviation sigma_L in pixels at incidence angle theta (rad).
  double LateralSigmaPx(double theta) const;
  /// width in pixels of the left invalid band at depth z (m): fx b / z (0 without the band).
  double InvalidBandPx(double z, double fx_px) const;
};

/// the preset `name` (one of kDepthNoisePresets) with `config`'s range overrides.
/// @throws ConfigError (key `key`) for an unknown preset or a bad range.
DepthNoiseModel DepthNoisePreset(const DepthNoiseConfig& config, const std::string& key);

/// per-pixel inputs of ApplyDepthNoise beyond the depth image. empty images mean "not
/// available": normals facing the camera, reflectance 1, not specular, transmittance 1, ambient
/// luminance default_ambient_cd_m2 times the reflectance.
struct DepthNoiseInputs {
  const ImageF* normal_O = nullptr;  ///< (H x W x 3) unit normal facing the camera, optical frame
  const ImageF* reflectance = nullptr;  ///< (H x W x 1) IR reflectance in [0, 1]; < 0 = specular
  const ImageF* transmittance =
      nullptr;  ///< (H x W x 1) one-way transmittance to the hit in [0, 1]
  /// (H x W x 1) luminance of the scene as the imagers see it (cd/m^2; e.g. the rendered
  /// radiance's Rec. 709 luminance, fog and all): the matcher's passive texture and ambient
  /// light. correlation matchers only.
  const ImageF* ambient_cd_m2 = nullptr;
  double fx = 500, fy = 500, cx = 0, cy = 0;  ///< intrinsics of the depth image (px)
  /// the depth camera, for exact (distorted) pixel rays; null = pinhole rays from fx fy cx cy.
  const Camera* camera = nullptr;
};

/// applies `model` to `depth_z` ((H x W x 1) z-depth in m, 0 = no hit) into `out` (same shape,
/// 0 = no return). `key` seeds the noise (e.g. HashKeys(seed, camera, frame)); rows are spread
/// over `pool` when given (results do not depend on it). `depth_z` is not modified.
/// @throws Error when an input image's size differs from `depth_z`'s.
void ApplyDepthNoise(const ImageF& depth_z, const DepthNoiseInputs& in,
                     const DepthNoiseModel& model, uint64_t key, ImageF* out,
                     ThreadPool* pool = nullptr);

/// optical depth tau = integral of sigma_t along the segment a_W -> b_W through one homogeneous
/// medium (channel mean of sigma_t_per_m; near-infrared sensors see roughly grey fog), clipped
/// to its region; height fog is integrated with 64 midpoint steps.
double HomogeneousOpticalDepth(const HomogeneousMedium& medium, const Eigen::Vector3d& a_W,
                               const Eigen::Vector3d& b_W);

/// one-way transmittance T from the camera to the hit of every pixel of `depth_z`
/// ((H x W x 1) z-depth, 0 = no hit -> 1) through all media of `effects`: homogeneous media in
/// closed form, voxel grids (smoke, steam) by ratio tracking (render/media/media_scene.h,
/// MediaScene::Transmittance; an unbiased per-pixel estimate, seeded by Rng(HashKeys(key,
/// pixel))); channel mean (near-infrared sensors see roughly grey media). the pixel ray comes
/// from `camera` (distortion and rolling shutter aware).
ImageF DepthTransmittance(const ImageF& depth_z, const Camera& camera, const EffectsFrame& effects,
                          uint64_t key, ThreadPool* pool = nullptr);

}  // namespace penumbra
