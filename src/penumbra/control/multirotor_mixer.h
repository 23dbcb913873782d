#pragma once
// motor mixing with saturation handling for multirotors: turns a desired collective
// thrust T (N) and body torques tau (N m) into per-rotor thrusts within each rotor's
// [min, max], using the pseudo-inverse of the allocation matrix B (MultirotorModel):
//   f = B^+ (T, tau_x, tau_y, tau_z),   B^+ = B^T (B B^T)^-1   (exact inverse for 4 rotors).
//
// when f does not fit, the mixer gives up authority in this order of importance:
//   1. roll and pitch torque (they steer the thrust vector: losing them loses the vehicle),
//   2. collective thrust (altitude is recovered once the attitude is right),
//   3. yaw torque (yaw is slow and decoupled from translation).
// with d = B^+ e_T (rotor thrusts per newton of collective), u = B^+ (0, tau_x, tau_y, 0)
// and y = B^+ (0, 0, 0, tau_z):
//   a. roll/pitch scale k in [0, 1]: the largest k for which some collective c puts every
//      k u_i + c d_i inside [min_i, max_i]; per rotor pair (i, j) this needs
//      k (u_j/d_j - u_i/d_i) <= max_j/d_j - min_i/d_i, which gives k in closed form.
//   b. collective: c = clamp(T, lo, hi), the feasible interval at scale k
//      (lo = max_i (min_i - k u_i)/d_i, hi = min_i (max_i - k u_i)/d_i): the collective is
//      lowered when rotors would exceed max and raised when they would fall below min
//      ("air mode" for roll and pitch).
//   c. yaw scale s in [0, 1]: the largest s with k u + c d + s y inside the limits, i.e.
//      yaw gets the headroom that is left (it never moves the collective).
// the priorities follow the desaturation of PX4's multicopter mixer (PX4 user guide,
// "Multicopter Airmode": roll/pitch authority kept by moving the collective, yaw last);
// the computation here is closed-form interval arithmetic on the allocation.

#include <Eigen/Core>
#include <span>
#include <vector>

namespace penumbra {

/// how much the last mix had to give up.
struct MixResult {
  double roll_pitch_scale = 1;      ///< k: fraction of the roll/pitch torque delivered
  double yaw_scale = 1;             ///< s: fraction of the yaw torque delivered
  double collective_n = 0;          ///< collective thrust delivered (N)
  bool collective_limited = false;  ///< collective differs from the request
  /// true when anything was given up.
  bool saturated() const { return roll_pitch_scale < 1 || yaw_scale < 1 || collective_limited; }
};

/// prioritised mixer for up to kMaxRotors rotors (see the file comment).
class MultirotorMixer {
 public:
  static constexpr int kMaxRotors = 16;

  MultirotorMixer() = default;
  /// @param allocation (4 x n) thrust/torque per newton of each rotor (MultirotorModel)
  /// @param min_thrust_n, max_thrust_n (n) limits of each rotor's thrust (N)
  /// @throws Error if n is not in [4, kMaxRotors], sizes differ, B B^T is singular or a
  ///         rotor does not share the collective thrust (B^+ e_T has an entry <= 0).
  MultirotorMixer(const Eigen::Matrix<double, 4, Eigen::Dynamic>& allocation,
                  std::vector<double> min_thrust_n, std::vector<double> max_thrust_n);

  /// per-rotor thrusts (N) into `thrust_n` (size n) for collective thrust `collective_n` (N,
  /// along the base z) and body torques `torque_Nm` (about the COM, base axes). no allocation.
  MixResult Mix(double collective_n, const Eigen::Vector3d& torque_Nm,
                std::span<double> thrust_n) const;

  /// the wrench (thrust, tau_x, tau_y, tau_z) that per-rotor thrusts `thrust_n` produce: B f.
  Eigen::Vector4d Wrench(std::span<const double> thrust_n) const;

  int num_rotors() const { return n_; }
  /// (n x 4) pseudo-inverse B^+.
  const Eigen::Matrix<double, Eigen::Dynamic, 4>& pseudo_inverse() const { return pinv_; }

 private:
  int n_ = 0;
  Eigen::Matrix<double, 4, Eigen::Dynamic> allocation_;
  Eigen::Matrix<double, Eigen::Dynamic, 4> pinv_;
  std::vector<double> min_, max_;
  std::vector<double> inv_d_;  ///< 1 / (B^+ e_T)_i
};

}  // namespace penumbra
