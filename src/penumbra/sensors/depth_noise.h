#pragma once
// active depth camera (RGB-D) noise: turns an exact z-depth image into what a structured-light,
// time-of-flight or active-stereo sensor reports. per pixel, in this order:
//
//   1. range: z outside [min_range_m, max_range_m] -> no return (0).
//   2. holes: incidence angle theta (between the pixel ray and the surface normal) above
//      max_incidence_deg -> no return; IR reflectance below min_reflectance -> no return;
//      specular surfaces (mirror-like: reflectance image flags them) -> no return.
//   3. participating media (fog, smoke; homogeneous and voxel grids): with one-way transmittance
//      T along the pixel ray to the surface (DepthTransmittance), the return survives with
//      probability T^2 = exp(-2 tau) (the emitted pattern and its reflection both cross the
//      medium), and never when T^2 < min_round_trip_transmittance.
//   4. lateral noise: the depth is read from the pixel displaced by N(0, sigma_L^2) in u and v
//      (rounded to the nearest pixel), which jags depth edges; flat surfaces are unaffected.
//   5. axial noise: z + N(0, sigma_z(z, theta)^2).
//
// presets (DepthNoisePreset):
//   kinect_v1       Nguyen, Izadi, Lovell, "Modeling Kinect sensor noise for improved 3D
//                   reconstruction and tracking", 3DIMPVT 2012, eqs. (1)-(3):
//                   sigma_z = 0.0012 + 0.0019 (z - 0.4)^2 + 0.0001 / sqrt(z) theta^2 / (pi/2 -
//                   theta)^2 m, sigma_L = 0.8 + 0.035 theta / (pi/2 - theta) px; range 0.5-4.0 m
//                   (Microsoft Kinect for Windows default mode 0.8-4 m; the paper measures from 0.5
//                   m).
//   kinect_v2       Fankhauser et al., "Kinect v2 for mobile robot navigation: evaluation and
//                   modeling", ICAR 2015: sigma_z = 1.5 - 0.5 z + 0.3 z^2 + 0.1 z^1.5 theta^2 /
//                   (pi/2 - theta)^2 mm, lateral sigma_L = 1.6 px (their reported ~constant
//                   lateral noise, rounded); range 0.5-4.5 m (Microsoft spec). the constants are
//                   quoted from memory of the paper and should be checked against it.
//   realsense_d435  Intel, "Tuning depth cameras for best performance" (Grunnet-Jepsen, Sweetser,
//                   Woodfill, Intel RealSense white paper, 2018), depth RMS error =
//                   z^2 subpixel / (f baseline) with subpixel = 0.08, baseline = 50 mm (D435
//                   datasheet, Intel RealSense D400 series product family datasheet rev. 0.7),
//                   f = the depth image's fx in pixels; lateral sigma_L = 0.5 px (edge
//                   fattening of the census matcher, our choice); range 0.2-10 m (datasheet min-Z
//                   ~0.2 m at 848x480, ideal range up to 10 m).
// all presets drop returns above 80 deg incidence, below 5 % IR reflectance and on specular
// (metallic > 0.5 and roughness < 0.2) surfaces; min_round_trip_transmittance = 0.05.
// random numbers: Rng(HashKeys(key, pixel)), so output is a pure function of the inputs.

#include <cstdint>
#include <string>

#include "penumbra/core/image.h"
#include "penumbra/core/thread_pool.h"
#include "penumbra/render/camera.h"
#include "penumbra/scene/effects_frame.h"
#include "penumbra/sensors/camera_sensor_config.h"

namespace penumbra {

/// parameters of one depth sensor (see the file comment for the presets and their sources).
struct DepthNoiseModel {
  enum class Axial { kKinectV1, kKinectV2, kStereoRms };
  std::string name;
  Axial axial = Axial::kStereoRms;
  double min_range_m = 0.2, max_range_m = 10;
  double lateral_sigma_px = 0.5;     ///< constant part of sigma_L
  double lateral_theta_coeff = 0.0;  ///< sigma_L += coeff theta / (pi/2 - theta)
  double stereo_subpixel = 0.08;     ///< kStereoRms: disparity RMS error, px
  double stereo_baseline_m = 0.05;   ///< kStereoRms: projector-camera / stereo baseline, m
  double max_incidence_deg = 80;     ///< larger incidence angles give no return
  double min_reflectance = 0.05;     ///< darker surfaces give no return
  double min_round_trip_transmittance = 0.05;  ///< below: no return in smoke / fog

  /// axial standard deviation sigma_z in m at z-depth z (m), incidence angle theta (rad), for a
  /// depth image with focal length fx_px.
  double AxialSigma(double z, double theta, double fx_px) const;
  /// lateral standard deviation sigma_L in pixels at incidence angle theta (rad).
  double LateralSigmaPx(double theta) const;
};

/// the preset `name` (one of kDepthNoisePresets) with `config`'s range overrides.
/// @throws ConfigError (key `key`) for an unknown preset or a bad range.
DepthNoiseModel DepthNoisePreset(const DepthNoiseConfig& config, const std::string& key);

/// per-pixel inputs of ApplyDepthNoise beyond the depth image. empty images mean "not
/// available": normals facing the camera, reflectance 1, not specular, transmittance 1.
struct DepthNoiseInputs {
  const ImageF* normal_O = nullptr;  ///< (H x W x 3) unit normal facing the camera, optical frame
  const ImageF* reflectance = nullptr;  ///< (H x W x 1) IR reflectance in [0, 1]; < 0 = specular
  const ImageF* transmittance =
      nullptr;  ///< (H x W x 1) one-way transmittance to the hit in [0, 1]
  double fx = 500, fy = 500, cx = 0, cy = 0;  ///< intrinsics of the depth image (px)
  /// the depth camera, for exact (distorted) pixel rays; null = pinhole rays from fx fy cx cy.
  const Camera* camera = nullptr;
};

/// applies `model` to `depth_z` ((H x W x 1) z-depth in m, 0 = no hit) into `out` (same shape,
/// 0 = no return). `key` seeds the noise (e.g. HashKeys(seed, camera, frame)); rows are spread
/// over `pool` when given (results do not depend on it).
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
/// closed form, voxel grids (smoke, steam) by ratio tracking (render/media_scene.h,
/// MediaScene::Transmittance; an unbiased per-pixel estimate, seeded by Rng(HashKeys(key,
/// pixel))); channel mean (near-infrared sensors see roughly grey media). the pixel ray comes
/// from `camera` (distortion and rolling shutter aware).
ImageF DepthTransmittance(const ImageF& depth_z, const Camera& camera, const EffectsFrame& effects,
                          uint64_t key, ThreadPool* pool = nullptr);

}  // namespace penumbra
