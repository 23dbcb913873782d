#include "penumbra/control/multirotor_mixer.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "penumbra/core/error.h"

namespace penumbra {

MultirotorMixer::MultirotorMixer(const Eigen::Matrix<double, 4, Eigen::Dynamic>& allocation,
                                 std::vector<double> min_thrust_n, std::vector<double> max_thrust_n)
    : n_(static_cast<int>(allocation.cols())),
      allocation_(allocation),
      min_(std::move(min_thrust_n)),
      max_(std::move(max_thrust_n)) {
  if (n_ < 4 || n_ > kMaxRotors)
    throw Error("MultirotorMixer: " + std::to_string(n_) + " rotors; expected 4 to " +
                std::to_string(kMaxRotors));
  if (static_cast<int>(min_.size()) != n_ || static_cast<int>(max_.size()) != n_)
    throw Error("MultirotorMixer: thrust limits for " + std::to_string(min_.size()) + " / " +
                std::to_string(max_.size()) + " rotors; expected " + std::to_string(n_));
  for (int i = 0; i < n_; ++i)
    if (!(min_[i] < max_[i]))
      throw Error("MultirotorMixer: rotor " + std::to_string(i) + " has min thrust >= max thrust");
  const Eigen::Matrix4d BBt = allocation_ * allocation_.transpose();
  const Eigen::FullPivLU<Eigen::Matrix4d> lu(BBt);
  if (!lu.isInvertible())
    throw Error(
        "MultirotorMixer: allocation has rank < 4; expected independent thrust and "
        "torques");
  pinv_ = allocation_.transpose() * lu.inverse();
  for (int i = 0; i < n_; ++i) {
    if (!(pinv_(i, 0) > 0))
      throw Error("MultirotorMixer: rotor " + std::to_string(i) +
                  " takes no share of the collective thrust; expected every rotor to lift");
    inv_d_.push_back(1.0 / pinv_(i, 0));
  }
}

MixResult MultirotorMixer::Mix(double collective_n, const Eigen::Vector3d& torque,
                               std::span<double> out) const {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  std::array<double, kMaxRotors> u, y;
  for (int i = 0; i < n_; ++i) {
    u[i] = pinv_(i, 1) * torque.x() + pinv_(i, 2) * torque.y();
    y[i] = pinv_(i, 3) * torque.z();
  }

  // collective interval that fits k u + c d inside the limits
  auto interval = [&](double k, double* lo, double* hi) {
    *lo = -kInf;
    *hi = kInf;
    for (int i = 0; i < n_; ++i) {
      *lo = std::max(*lo, (min_[i] - k * u[i]) * inv_d_[i]);
      *hi = std::min(*hi, (max_[i] - k * u[i]) * inv_d_[i]);
    }
  };
  double lo, hi, k = 1;
  interval(1, &lo, &hi);
  if (lo > hi) {
    // a. roll/pitch scale: every pair (i, j) needs lo_i(k) <= hi_j(k), i.e.
    //    k (u_j/d_j - u_i/d_i) <= max_j/d_j - min_i/d_i
    for (int i = 0; i < n_; ++i)
      for (int j = 0; j < n_; ++j) {
        const double coef = u[j] * inv_d_[j] - u[i] * inv_d_[i];
        if (coef <= 0) continue;
        k = std::min(k, (max_[j] * inv_d_[j] - min_[i] * inv_d_[i]) / coef);
      }
    k = std::max(k, 0.0);
    interval(k, &lo, &hi);
  }

  // b. collective within the feasible interval at scale k
  double c = collective_n;
  if (lo > hi) {
    c = 0.5 * (lo + hi);  // only through rounding, or limits no collective can satisfy
  } else {
    c = std::clamp(collective_n, lo, hi);
  }

  // c. yaw gets the headroom that is left
  double s = 1;
  for (int i = 0; i < n_; ++i) {
    const double base = k * u[i] + c * pinv_(i, 0);
    if (y[i] > 0) {
      s = std::min(s, (max_[i] - base) / y[i]);
    } else if (y[i] < 0) {
      s = std::min(s, (min_[i] - base) / y[i]);
    }
  }
  s = std::max(s, 0.0);

  for (int i = 0; i < n_; ++i)
    out[i] = std::clamp(k * u[i] + c * pinv_(i, 0) + s * y[i], min_[i], max_[i]);

  MixResult r;
  r.roll_pitch_scale = k;
  r.yaw_scale = s;
  r.collective_n = c;
  r.collective_limited = c != collective_n;
  return r;
}

Eigen::Vector4d MultirotorMixer::Wrench(std::span<const double> thrust_n) const {
  Eigen::Vector4d w = Eigen::Vector4d::Zero();
  for (int i = 0; i < n_; ++i) w += allocation_.col(i) * thrust_n[i];
  return w;
}

}  // namespace penumbra
