#include "penumbra/render/camera.h"

#include <cmath>

#include "penumbra/core/error.h"

namespace penumbra {

Camera::Camera(const Pose& X_WO, const CameraIntrinsics& intrinsics)
    : X_WO_(X_WO), intrinsics_(intrinsics) {
  const CameraIntrinsics& k = intrinsics;
  if (k.width < 1 || k.height < 1)
    throw ConfigError("", 0, "camera.intrinsics",
                      "image size " + std::to_string(k.width) + "x" + std::to_string(k.height) +
                          "; expected width, height >= 1");
  if (!(k.fx > 0) || !(k.fy > 0) || !std::isfinite(k.fx) || !std::isfinite(k.fy) ||
      !std::isfinite(k.cx) || !std::isfinite(k.cy))
    throw ConfigError("", 0, "camera.intrinsics",
                      "fx, fy must be positive and fx, fy, cx, cy finite");
  const Eigen::Matrix3d R = X_WO.linear();
  o_W_ = X_WO.translation().cast<float>();
  ex_W_ = R.col(0).cast<float>();
  ey_W_ = R.col(1).cast<float>();
  ez_W_ = R.col(2).cast<float>();
  cx_ = static_cast<float>(k.cx);
  cy_ = static_cast<float>(k.cy);
  inv_fx_ = static_cast<float>(1.0 / k.fx);
  inv_fy_ = static_cast<float>(1.0 / k.fy);
}

bool Camera::Project(const Eigen::Vector3d& p_W, Eigen::Vector2d* uv, double* z) const {
  const Eigen::Vector3d p_O = X_WO_.inverse() * p_W;
  if (!(p_O.z() > 0)) return false;
  *uv = Eigen::Vector2d(intrinsics_.fx * p_O.x() / p_O.z() + intrinsics_.cx,
                        intrinsics_.fy * p_O.y() / p_O.z() + intrinsics_.cy);
  *z = p_O.z();
  return true;
}

}  // namespace penumbra
