#include "penumbra/control/quadruped_leg_kinematics.h"

#include <algorithm>
#include <cmath>

namespace penumbra {

Eigen::Vector3d LegForwardKinematics(const LegGeometry& leg, const Eigen::Vector3d& q) {
  const double l1 = leg.abduction_m, l2 = leg.thigh_m, l3 = leg.calf_m;
  const double x = -l2 * std::sin(q[1]) - l3 * std::sin(q[1] + q[2]);
  const double zp = -l2 * std::cos(q[1]) - l3 * std::cos(q[1] + q[2]);
  const double c1 = std::cos(q[0]), s1 = std::sin(q[0]);
  return {x, l1 * c1 - zp * s1, l1 * s1 + zp * c1};
}

Eigen::Matrix3d LegJacobian(const LegGeometry& leg, const Eigen::Vector3d& q) {
  const double l1 = leg.abduction_m, l2 = leg.thigh_m, l3 = leg.calf_m;
  const double s2 = std::sin(q[1]), c2 = std::cos(q[1]);
  const double s23 = std::sin(q[1] + q[2]), c23 = std::cos(q[1] + q[2]);
  const double zp = -l2 * c2 - l3 * c23;
  const double c1 = std::cos(q[0]), s1 = std::sin(q[0]);
  Eigen::Matrix3d J;
  // d/dq1: derivative of the abduction rotation applied to (x, l1, z')
  J.col(0) << 0, -l1 * s1 - zp * c1, l1 * c1 - zp * s1;
  // d/dq2, d/dq3: in-plane derivatives (dx, 0, dz') rotated by the abduction
  const double dx2 = -l2 * c2 - l3 * c23, dz2 = l2 * s2 + l3 * s23;
  const double dx3 = -l3 * c23, dz3 = l3 * s23;
  J.col(1) << dx2, -dz2 * s1, dz2 * c1;
  J.col(2) << dx3, -dz3 * s1, dz3 * c1;
  return J;
}

bool LegInverseKinematics(const LegGeometry& leg, const Eigen::Vector3d& p_H, Eigen::Vector3d* q) {
  const double l1 = leg.abduction_m, l2 = leg.thigh_m, l3 = leg.calf_m;
  bool reachable = true;
  // abduction: the foot lies on a circle of radius sqrt(l1^2 + z'^2) about the x axis
  const double py = p_H.y(), pz = p_H.z();
  const double min_leg = std::max(std::abs(l2 - l3), 0.05 * (l2 + l3));
  double d2 = py * py + pz * pz - l1 * l1;
  if (d2 < min_leg * min_leg) {
    d2 = min_leg * min_leg;
    reachable = false;
  }
  const double zp = -std::sqrt(d2);
  // q1 = atan2(pz, py) - atan2(z', l1), as one atan2 of the angle between the vectors
  const double q1 = std::atan2(l1 * pz - zp * py, l1 * py + zp * pz);
  // sagittal plane: two-link arm from the thigh axis to the foot at (x, z')
  double x = p_H.x(), z = zp;
  double r2 = x * x + z * z;
  const double r_max = (l2 + l3) * (1 - 1e-9), r_min = std::max(std::abs(l2 - l3), 1e-6) + 1e-9;
  if (r2 > r_max * r_max || r2 < r_min * r_min) {
    const double r = std::sqrt(r2);
    const double rc = std::clamp(r, r_min, r_max);
    if (r < 1e-12) {
      x = 0;
      z = -rc;
    } else {
      x *= rc / r;
      z *= rc / r;
    }
    r2 = rc * rc;
    reachable = false;
  }
  const double c3 = std::clamp((r2 - l2 * l2 - l3 * l3) / (2 * l2 * l3), -1.0, 1.0);
  const double q3 = -std::acos(c3);
  const double s3 = -std::sqrt(std::max(0.0, 1 - c3 * c3));  // sin(q3), q3 <= 0
  // q2 = atan2(-x, -z') - atan2(l3 s3, l2 + l3 c3), again as one atan2
  const double wx = l2 + l3 * c3, wy = l3 * s3;
  const double q2 = std::atan2(-x * wx + z * wy, -z * wx - x * wy);
  *q = Eigen::Vector3d(q1, q2, q3);
  return reachable;
}

}  // namespace penumbra
