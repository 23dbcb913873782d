#pragma once
// IMU noise: the Kalibr / Allan-variance model per axis (Kalibr wiki, "IMU Noise Model";
// IEEE Std 952-1997 Annex C). a measurement is
//   w~(t) = w(t) + b(t) + n(t),  n white with density sigma_c,  b' = sigma_bc * white,
// sampled at period dt:
//   w~_k = w_k + b_k + sigma_d n_k,       sigma_d = sigma_c / sqrt(dt)
//   b_{k+1} = b_k + sigma_bd m_k,          sigma_bd = sigma_bc sqrt(dt)
// with n_k, m_k ~ N(0, 1). the true values come from MuJoCo's accelerometer (specific force
// in the site frame: +g up at rest, 0 in free fall) and gyro (angular velocity in the site
// frame) sensors that the composer adds at the IMU's site.
//
// Allan deviation of the result (overlapping, see allan_deviation.h): sigma_c / sqrt(tau)
// (white noise, slope -1/2; ADEV(1 s) = sigma_c) plus sigma_bc sqrt(tau / 3) (random walk,
// slope +1/2).

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

namespace penumbra {

/// continuous-time noise parameters of one IMU (same for the three axes).
struct ImuNoiseConfig {
  double accel_noise_density = 0;  ///< sigma_c, m/s^2/sqrt(Hz) (>= 0)
  double accel_random_walk = 0;    ///< sigma_bc, m/s^3/sqrt(Hz) (>= 0)
  double gyro_noise_density = 0;   ///< sigma_c, rad/s/sqrt(Hz) (>= 0)
  double gyro_random_walk = 0;     ///< sigma_bc, rad/s^2/sqrt(Hz) (>= 0)

  /// @throws Error naming the first negative or non-finite parameter.
  void ValidateOrThrow() const;
};

/// presets:
///  - consumer_mems (Bosch BMI088 class, datasheet BST-BMI088-DS001): accel 175 ug/sqrt(Hz)
///    = 1.72e-3 m/s^2/sqrt(Hz), gyro 0.014 deg/s/sqrt(Hz) = 2.44e-4 rad/s/sqrt(Hz); the
///    datasheet gives no bias stability, so the random walks assume a consumer-class bias
///    instability of 40 ug and 5 deg/h reached at tau = 1000 s on the +1/2 slope
///    (sigma_bc = B sqrt(3 / 1000)): 2.15e-5 m/s^3/sqrt(Hz), 1.33e-6 rad/s^2/sqrt(Hz);
///  - tactical (Analog Devices ADIS16495 class, datasheet Rev. B): angle random walk
///    0.12 deg/sqrt(h) = 3.49e-5 rad/s/sqrt(Hz), velocity random walk 0.008 m/s/sqrt(h)
///    = 1.33e-4 m/s^2/sqrt(Hz); bias instability 0.8 deg/h and 3.2 ug mapped to random
///    walks as above: 2.13e-7 rad/s^2/sqrt(Hz), 1.72e-6 m/s^3/sqrt(Hz);
///  - ideal: no noise.
/// @throws Error for an unknown name (listing the names).
ImuNoiseConfig ImuPreset(const std::string& name);
/// names accepted by ImuPreset.
const std::vector<std::string>& ImuPresetNames();

/// one IMU sample.
struct ImuSample {
  Eigen::Vector3d accel_m_s2{0, 0, 0};  ///< specific force, IMU (site) frame
  Eigen::Vector3d gyro_rad_s{0, 0, 0};  ///< angular velocity, IMU (site) frame
};

/// applies the noise model to a sequence of samples; keeps the bias state.
class ImuNoiseModel {
 public:
  /// @throws Error from config.ValidateOrThrow(); if sample_period_sec is not > 0.
  ImuNoiseModel(ImuNoiseConfig config, double sample_period_sec, uint64_t stream_seed);

  /// returns the noisy version of sample k (call with k = 0, 1, 2, ... in order; the bias
  /// advances once per call). draws come from Rng(HashKeys(stream_seed, k)).
  ImuSample Apply(int64_t k, const ImuSample& truth);

  const Eigen::Vector3d& accel_bias() const { return accel_bias_; }
  const Eigen::Vector3d& gyro_bias() const { return gyro_bias_; }
  const ImuNoiseConfig& config() const { return config_; }

 private:
  ImuNoiseConfig config_;
  double dt_;
  uint64_t seed_;
  Eigen::Vector3d accel_bias_{0, 0, 0}, gyro_bias_{0, 0, 0};
};

}  // namespace penumbra
