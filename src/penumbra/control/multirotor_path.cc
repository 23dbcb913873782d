#include "penumbra/control/multirotor_path.h"

#include <algorithm>
#include <cmath>

#include "penumbra/core/error.h"

namespace penumbra {

MultirotorPath::MultirotorPath(const Eigen::Vector3d& start, std::vector<Eigen::Vector3d> points,
                               double speed_m_s, double accel_m_s2) {
  if (!(std::isfinite(speed_m_s) && speed_m_s > 0 && std::isfinite(accel_m_s2) && accel_m_s2 > 0))
    throw Error("MultirotorPath: speed and acceleration must be finite and > 0");
  vertices_.reserve(points.size() + 1);
  vertices_.push_back(start);
  for (auto& p : points) vertices_.push_back(p);
  // each ramp (rest -> v or v -> rest) takes T_a = pi v / (2 a) and covers v T_a / 2
  double t = 0;
  for (size_t k = 0; k + 1 < vertices_.size(); ++k) {
    const double L = (vertices_[k + 1] - vertices_[k]).norm();
    double v = speed_m_s;
    double t_ramp = M_PI * v / (2 * accel_m_s2);
    double t_cruise = 0;
    if (L >= v * t_ramp) {
      t_cruise = (L - v * t_ramp) / v;
    } else {
      v = std::sqrt(2 * accel_m_s2 * L / M_PI);
      t_ramp = M_PI * v / (2 * accel_m_s2);
    }
    t += 2 * t_ramp + t_cruise;
    length_.push_back(L);
    t_accel_.push_back(t_ramp);
    v_peak_.push_back(v);
    end_time_.push_back(t);
  }
}

PathSample MultirotorPath::Sample(double t_sec) const {
  PathSample s;
  if (end_time_.empty()) {
    s.position = vertices_.empty() ? Eigen::Vector3d::Zero() : vertices_.back();
    return s;
  }
  if (!(t_sec < end_time_.back())) {
    s.position = vertices_.back();
    s.segment = static_cast<int>(end_time_.size()) - 1;
    return s;
  }
  t_sec = std::max(t_sec, 0.0);
  const size_t k = std::upper_bound(end_time_.begin(), end_time_.end(), t_sec) - end_time_.begin();
  s.segment = static_cast<int>(k);
  const double L = length_[k];
  if (L <= 0) {
    s.position = vertices_[k + 1];
    return s;
  }
  const double t0 = k == 0 ? 0 : end_time_[k - 1];
  const double T = end_time_[k] - t0;
  const double tau = t_sec - t0;
  const double ta = t_accel_[k], vp = v_peak_[k];
  // harmonic ramp over [0, ta]: v = vp (1 - cos(pi x / ta)) / 2
  auto ramp = [&](double x, double* d, double* sp, double* ac, double* jk) {
    const double w = M_PI / ta;
    *d = 0.5 * vp * (x - std::sin(w * x) / w);
    *sp = 0.5 * vp * (1 - std::cos(w * x));
    *ac = 0.5 * vp * w * std::sin(w * x);
    *jk = 0.5 * vp * w * w * std::cos(w * x);
  };
  double dist, speed, acc, jerk;
  if (tau < ta) {
    ramp(tau, &dist, &speed, &acc, &jerk);
  } else if (tau < T - ta) {
    dist = 0.5 * vp * ta + vp * (tau - ta);
    speed = vp;
    acc = 0;
    jerk = 0;
  } else {
    // mirrored ramp: d/dtau of -acc(T - tau) is +jerk(T - tau)
    ramp(T - tau, &dist, &speed, &acc, &jerk);
    dist = L - dist;
    acc = -acc;
  }
  const Eigen::Vector3d dir = (vertices_[k + 1] - vertices_[k]) / L;
  s.position = vertices_[k] + std::clamp(dist, 0.0, L) * dir;
  s.velocity = speed * dir;
  s.acceleration = acc * dir;
  s.jerk = jerk * dir;
  return s;
}

}  // namespace penumbra
