#include "penumbra/core/pose.h"

#include <cmath>

namespace penumbra {

Pose PoseFromXyzRpyDeg(const Eigen::Vector3d& xyz, const Eigen::Vector3d& rpy_deg) {
  const Eigen::Vector3d r = rpy_deg * (M_PI / 180.0);
  Pose X = Pose::Identity();
  X.linear() = (Eigen::AngleAxisd(r.z(), Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(r.y(), Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(r.x(), Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  X.translation() = xyz;
  return X;
}

Pose PoseFromPosQuat(const double pos[3], const double quat_wxyz[4]) {
  Pose X = Pose::Identity();
  X.linear() =
      Eigen::Quaterniond(quat_wxyz[0], quat_wxyz[1], quat_wxyz[2], quat_wxyz[3]).normalized().toRotationMatrix();
  X.translation() = Eigen::Vector3d(pos[0], pos[1], pos[2]);
  return X;
}

Eigen::Matrix3d RotationMujocoCameraFromOptical() {
  // optical x = cam x, optical y = -cam y, optical z = -cam z
  return Eigen::Vector3d(1, -1, -1).asDiagonal();
}

Eigen::Matrix3d RotationBodyFromOptical() {
  // columns are the optical axes expressed in the body frame:
  // x_opt = -y_body (right), y_opt = -z_body (down), z_opt = x_body (forward)
  Eigen::Matrix3d R;
  R << 0, 0, 1,
      -1, 0, 0,
      0, -1, 0;
  return R;
}

}  // namespace penumbra
