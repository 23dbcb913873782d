#include "penumbra/compose/mjcf_frames.h"

#include <cmath>

namespace penumbra::compose {
namespace {

constexpr double kEps = 1e-14;  // MuJoCo mjEPS

bool Sized(const std::optional<std::vector<double>>& v, size_t n) { return v && v->size() == n; }

}  // namespace

Eigen::Quaterniond QuatFromZAxis(const Eigen::Vector3d& vec) {
  const Eigen::Vector3d z = vec.normalized();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ().cross(z);
  const double s = axis.norm();
  if (s < 1e-10) {
    axis = Eigen::Vector3d::UnitX();
  } else {
    axis /= s;
  }
  const double ang = std::atan2(s, z.z());
  return Eigen::Quaterniond(std::cos(ang / 2), axis.x() * std::sin(ang / 2),
                            axis.y() * std::sin(ang / 2), axis.z() * std::sin(ang / 2));
}

std::optional<Eigen::Quaterniond> ResolveOrientation(const OrientationSpec& spec, bool degree,
                                                     const std::string& eulerseq,
                                                     std::string* error) {
  const double to_rad = degree ? M_PI / 180.0 : 1.0;
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  if (spec.quat) {
    if (!Sized(spec.quat, 4)) {
      *error = "quat needs 4 numbers";
      return std::nullopt;
    }
    const auto& v = *spec.quat;
    q = Eigen::Quaterniond(v[0], v[1], v[2], v[3]);
    if (q.norm() < kEps) {
      *error = "quat is zero";
      return std::nullopt;
    }
    q.normalize();
  }
  if (spec.axisangle) {
    if (!Sized(spec.axisangle, 4)) {
      *error = "axisangle needs 4 numbers";
      return std::nullopt;
    }
    const auto& v = *spec.axisangle;
    Eigen::Vector3d axis(v[0], v[1], v[2]);
    if (axis.norm() < kEps) {
      *error = "axisangle axis too small";
      return std::nullopt;
    }
    axis.normalize();
    const double half = v[3] * to_rad / 2;
    q = Eigen::Quaterniond(std::cos(half), std::sin(half) * axis.x(), std::sin(half) * axis.y(),
                           std::sin(half) * axis.z());
  }
  if (spec.xyaxes) {
    if (!Sized(spec.xyaxes, 6)) {
      *error = "xyaxes needs 6 numbers";
      return std::nullopt;
    }
    const auto& v = *spec.xyaxes;
    Eigen::Vector3d x(v[0], v[1], v[2]);
    Eigen::Vector3d y(v[3], v[4], v[5]);
    if (x.norm() < kEps) {
      *error = "xyaxes x axis too small";
      return std::nullopt;
    }
    x.normalize();
    y -= x * x.dot(y);
    if (y.norm() < kEps) {
      *error = "xyaxes y axis too small";
      return std::nullopt;
    }
    y.normalize();
    const Eigen::Vector3d z = x.cross(y);
    Eigen::Matrix3d r;
    r.col(0) = x;
    r.col(1) = y;
    r.col(2) = z.normalized();
    q = Eigen::Quaterniond(r).normalized();
  }
  if (spec.zaxis) {
    if (!Sized(spec.zaxis, 3)) {
      *error = "zaxis needs 3 numbers";
      return std::nullopt;
    }
    const auto& v = *spec.zaxis;
    const Eigen::Vector3d z(v[0], v[1], v[2]);
    if (z.norm() < kEps) {
      *error = "zaxis too small";
      return std::nullopt;
    }
    q = QuatFromZAxis(z);
  }
  if (spec.euler) {
    if (!Sized(spec.euler, 3)) {
      *error = "euler needs 3 numbers";
      return std::nullopt;
    }
    if (eulerseq.size() != 3) {
      *error = "eulerseq must have 3 letters";
      return std::nullopt;
    }
    q = Eigen::Quaterniond::Identity();
    for (int i = 0; i < 3; ++i) {
      const double half = (*spec.euler)[i] * to_rad / 2;
      Eigen::Quaterniond r(std::cos(half), 0, 0, 0);
      const char c = eulerseq[i];
      if (c == 'x' || c == 'X') {
        r.x() = std::sin(half);
      } else if (c == 'y' || c == 'Y') {
        r.y() = std::sin(half);
      } else if (c == 'z' || c == 'Z') {
        r.z() = std::sin(half);
      } else {
        *error = "eulerseq can only contain x, y, z, X, Y, Z";
        return std::nullopt;
      }
      // lowercase: rotating axes (post-multiply); uppercase: fixed axes (pre-multiply)
      q = (c == 'x' || c == 'y' || c == 'z') ? q * r : r * q;
    }
    q.normalize();
  }
  return q;
}

std::vector<double> QuatToVector(const Eigen::Quaterniond& q) {
  return {q.w(), q.x(), q.y(), q.z()};
}

}  // namespace penumbra::compose
