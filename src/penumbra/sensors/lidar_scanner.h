#pragma once
// ray-traced LiDAR: one scan of a LidarPattern against the geometry the cameras see, through the
// backend-neutral RayQuery (render/ray_query.h; beams traced in batches of neighbours), with
// per-beam timestamps, motion distortion, intensity, range noise, dropout and adverse media
// (attenuation, fog/smoke false returns, rain/snow returns).
//
// frames and motion: the caller gives X_WS(t), the sensor pose in the world for t in
// [0, scan period] after the scan start (e.g. interpolated between the scan-start and the
// scan-end snapshots with InterpolatePose). every beam is traced from the pose at its firing
// time; its point is range * direction in the sensor frame at that time (what a driver
// reports without motion compensation), so a moving sensor's scan is motion-distorted. the
// rest of the world is posed once (the RayQuery as the caller updated it, normally from the
// scan-start snapshot) and particles are frozen at their EffectsFrame positions.
//
// return model (single return, "strongest" mode), in one normalised power unit: the power
// backscattered per steradian by the target, times the two-way transmittance, over range^2
// (the LiDAR equation without the constant C_A P_0; Hahner et al. 2021, eq. 2-6):
//  - surface (hard target): P_hard = (rho cos(theta) / pi) T^2(R) / R^2, with rho the
//    luminance (Rec. 709 weights) of the material's base colour (textures are not sampled),
//    theta the incidence angle (Lambertian), T^2(R) = exp(-2 int_0^R sigma_t ds);
//  - participating media (soft target, Hahner, Sakaridis, Bijelic, et al., "Fog Simulation
//    on Real LiDAR Point Clouds for 3D Object Detection in Adverse Weather", ICCV 2021,
//    sec. 3): P_soft(R) = beta(R) L xi(R) T^2(R) / R^2 with backscatter coefficient
//    beta = albedo sigma_t 0.046 / ln(20) (their beta = 0.046 / MOR with
//    sigma_t = ln(20) / MOR), effective pulse length L = c tau_H / 2 (the integral of their
//    sin^2 pulse of half-power width tau_H) and their bistatic overlap
//    xi(R) = clamp((R - R_1) / (R_2 - R_1), 0, 1). simplification: instead of convolving the
//    pulse with the medium, P_soft is sampled at 48 ranges in [R_1, R_end] (R_end = the hard
//    target or max range) and its maximum taken; media extinction uses the rgb channel 0
//    (red, closest to the 905 nm NIR; fog droplets scatter nearly independently of
//    wavelength). as in Hahner et al., when the soft peak beats the hard target the point is
//    replaced by a false return at the peak's range. the hard target's T^2 reuses the
//    march's optical depth (midpoint rule: exact for uniform media; height fog and voxel
//    grids are sampled at the 48 points, grids at the nearest voxel); the march stops early
//    where nothing beyond can reach the detection floor (the result is then unchanged);
//  - particles (EffectsFrame rain/snow/sparks): a sphere within the beam cone (divergence)
//    returns P_p = (rho_p / pi) min(1, (r_p / r_beam)^2) T^2 / R^2, r_beam = R tan(div / 2);
//    rho_p = 0.02 for rain (Fresnel reflectance of water at normal incidence), the colour's
//    luminance for snow and sparks.
//  - mixed returns: a beam near an edge is traced along its axis and along footprint_rays
//    more rays on a ring of 0.7 half-divergences (the rms radius of a uniform disc), each
//    sampling the hard target with equal weight. near an edge: a neighbouring beam (the next
//    one either way, the neighbouring column of a spinning sensor, within 2.5 deg and a batch
//    of 256 beams)
//    hits where it misses or the other way round, or hits off its tangent plane by more than
//    5 cm + 2 % of the range; other beams (continuous surfaces) trace their axis alone. returns
//    whose ranges differ by less than the pulse length L = c tau_H / 2 arrive as one pulse: the
//    strongest such group is the hard-target candidate, with the group's mean power over the
//    footprint and its power-weighted mean range. on a depth edge closer than L to its background
//    the point lands between the two surfaces (a mixed or "flying" point); farther apart the two
//    are separate pulses and the stronger wins (single strongest return). on a continuous surface
//    the range is the axis's to within the footprint's spread.
//  - multipath is not modelled: with a narrow receiver field that sees only the laser spot,
//    light that reaches the spot from a second diffuse surface scales with the spot's area
//    over the squared distance (well below 1e-3 in a room corner), so Lambertian corners
//    give no measurable bias; ghost points behind mirrors and glass (specular multipath)
//    are not traced.
// detection: the strongest candidate plus receiver noise N(0, (receiver_noise P_th)^2) must
// reach P_th = (reference_reflectivity / pi) / max_range^2, the power of a reference target
// at maximum range; a beam is also dropped with dropout_probability, and when its
// intensity is below min_intensity. range noise N(0, range_noise_stddev_m^2) is added along
// the beam. intensity = pi P R^2 (range-normalised, default: the target's apparent
// reflectivity times T^2, 1 for a white wall at normal incidence in clear air) or pi P (1 m)^2
// when intensity_range_normalized is false (raw 1 / R^2 falloff).
//
// determinism: beam i of scan k draws from Rng(HashKeys(stream_seed, k, i)).

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "penumbra/core/pose.h"
#include "penumbra/render/ray_query.h"
#include "penumbra/scene/effects_frame.h"
#include "penumbra/sensors/lidar_pattern.h"

namespace penumbra {

/// what a point came from.
enum class LidarReturnKind : uint8_t { kSurface = 0, kMedium = 1, kParticle = 2 };

/// one point of a scan (sensor frame at the beam's firing time, REP-103).
struct LidarPoint {
  float x = 0, y = 0, z = 0;  ///< m
  float intensity = 0;        ///< see the header comment (dimensionless)
  uint16_t ring = 0;          ///< laser index (0 = lowest for spinning sensors)
  float time = 0;             ///< s since the scan start
  LidarReturnKind kind = LidarReturnKind::kSurface;
  int32_t beam = 0;  ///< index into LidarPattern::beams
};

/// one scan.
struct LidarScan {
  std::vector<LidarPoint> points;  ///< in beam order
  int64_t rays = 0;                ///< beams traced
  int64_t medium_returns = 0;      ///< false returns from fog / smoke
  int64_t particle_returns = 0;    ///< returns from rain / snow / sparks
};

/// the most footprint rays a beam may trace besides its axis (LidarConfig::footprint_rays).
inline constexpr int kMaxFootprintRays = 16;

/// LiDAR model parameters beyond the scan pattern.
struct LidarConfig {
  LidarPattern pattern;
  double range_noise_stddev_m = 0.0;  ///< Gaussian range noise, m (>= 0)
  double dropout_probability = 0.0;   ///< random beam loss in [0, 1]
  double min_intensity = 0.0;         ///< returns with lower intensity are dropped (>= 0)
  bool intensity_range_normalized = true;
  double reference_reflectivity = 0.1;      ///< reflectivity detected at max range (0, 1]
  double receiver_noise = 0.0;              ///< receiver noise stddev / P_th (>= 0)
  bool media = true;                        ///< model media and particles
  double pulse_half_power_width_ns = 20.0;  ///< tau_H (Hahner et al.: 20 ns), > 0
  double overlap_start_m = 1.0;             ///< R_1 of xi(R)
  double overlap_full_m = 5.0;              ///< R_2 of xi(R) (> R_1)
  /// rays on the beam's footprint besides its axis (mixed returns at edges; 0 = the axis
  /// alone), in [0, kMaxFootprintRays]
  int footprint_rays = 4;

  /// @throws Error naming the parameter and its valid range.
  void ValidateOrThrow() const;
};

/// sensor pose in the world, X_WS, at time t (s) since the scan start.
using SensorPoseAt = std::function<Pose(double t_sec)>;

/// X_WS interpolated between `a` (s = 0) and `b` (s = 1): translation linear, rotation slerp.
Pose InterpolatePose(const Pose& a, const Pose& b, double s);

/// traces scans of one LiDAR.
class LidarScanner {
 public:
  /// @throws Error from config.ValidateOrThrow().
  LidarScanner(LidarConfig config, uint64_t stream_seed);

  /// traces scan `scan_index` in `scene` (already posed by the caller) with media and
  /// particles from `effects` (null = clear); `X_WS` gives the sensor pose over the scan.
  void Scan(const RayQuery& scene, const EffectsFrame* effects, const SensorPoseAt& X_WS,
            int64_t scan_index, LidarScan* out) const;

  const LidarConfig& config() const { return config_; }
  /// detection threshold P_th (normalised power units).
  double threshold_power() const { return p_th_; }

 private:
  LidarConfig config_;
  uint64_t seed_;
  double p_th_ = 0;
  std::vector<Eigen::Vector3f> dir_S_;  // unit beam directions
  // angular buckets of beams (azimuth x elevation, kBinDeg), for particle lookup
  int n_az_ = 0, n_el_ = 0;
  std::vector<int> bin_start_, bin_beams_;
  double el_min_deg_ = -90, el_max_deg_ = 90;  // elevation span of the beams
};

}  // namespace penumbra
