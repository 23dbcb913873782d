#include "penumbra/render/camera/camera.h"

#include <cmath>

#include "penumbra/core/error.h"
#include "penumbra/render/camera/camera_distortion.h"

namespace penumbra {

Camera::Camera(const Pose& X_WO, const CameraIntrinsics& intrinsics, const CameraMotion& motion)
    : X_WO_(X_WO), intrinsics_(intrinsics), motion_(motion) {
  const CameraIntrinsics& k = intrinsics;
  if (k.width < 1 || k.height < 1)
    throw ConfigError("", 0, "camera.intrinsics",
                      "image size " + std::to_string(k.width) + "x" + std::to_string(k.height) +
                          "; expected width, height >= 1");
  if (!(k.fx > 0) || !(k.fy > 0) || !std::isfinite(k.fx) || !std::isfinite(k.fy) ||
      !std::isfinite(k.cx) || !std::isfinite(k.cy))
    throw ConfigError("", 0, "camera.intrinsics",
                      "fx, fy must be positive and fx, fy, cx, cy finite");
  // the fold check costs ~2 ms at 640 x 480: skip it for the intrinsics this thread last passed
  // (a camera is rebuilt for every frame and sub-frame with the same intrinsics)
  thread_local CameraIntrinsics last_valid;
  thread_local bool have_last_valid = false;
  const bool same_as_last =
      have_last_valid && k.width == last_valid.width && k.height == last_valid.height &&
      k.fx == last_valid.fx && k.fy == last_valid.fy && k.cx == last_valid.cx &&
      k.cy == last_valid.cy && k.k1 == last_valid.k1 && k.k2 == last_valid.k2 &&
      k.p1 == last_valid.p1 && k.p2 == last_valid.p2 && k.k3 == last_valid.k3;
  if (k.has_distortion() && !same_as_last) {
    if (auto problem = FindDistortionProblem(k))
      throw ConfigError("", 0, "camera.intrinsics",
                        *problem + "; expected a distortion that is one-to-one over the image");
    last_valid = k;
    have_last_valid = true;
  }
  if (!(motion.end_sec >= 0) || !std::isfinite(motion.end_sec) || !std::isfinite(motion.time_sec) ||
      !(motion.line_time_sec >= 0) || !std::isfinite(motion.line_time_sec))
    throw ConfigError("", 0, "camera.motion",
                      "end_sec and line_time_sec must be finite and >= 0, time_sec finite");
  const Eigen::Matrix3d R = X_WO.linear();
  o_W_ = X_WO.translation().cast<float>();
  ex_W_ = R.col(0).cast<float>();
  ey_W_ = R.col(1).cast<float>();
  ez_W_ = R.col(2).cast<float>();
  cx_ = static_cast<float>(k.cx);
  cy_ = static_cast<float>(k.cy);
  inv_fx_ = static_cast<float>(1.0 / k.fx);
  inv_fy_ = static_cast<float>(1.0 / k.fy);
  pixel_spread_rad_ = static_cast<float>(1.0 / (std::sqrt(k.fx) * std::sqrt(k.fy)));
  q0_ = Eigen::Quaterniond(R);
  q1_ = Eigen::Quaterniond(motion.X_WO_end.linear());
  slow_ = k.has_distortion() || motion.moving();
}

Eigen::Vector2d Camera::Unproject(double u, double v) const {
  const CameraIntrinsics& k = intrinsics_;
  const double xd = (u - k.cx) / k.fx, yd = (v - k.cy) / k.fy;
  if (!k.has_distortion()) return {xd, yd};
  double x, y;
  UndistortNormalized(k, xd, yd, &x, &y);  // converges: checked over the image at construction
  return {x, y};
}

Pose Camera::PoseAtRow(double v) const {
  if (!motion_.moving()) return X_WO_;
  const double s = motion_.time_sec + motion_.line_time_sec * v;
  const double a = s / motion_.end_sec;
  Pose X = Pose::Identity();
  X.linear() = q0_.slerp(a, q1_).toRotationMatrix();
  X.translation() = (1.0 - a) * X_WO_.translation() + a * motion_.X_WO_end.translation();
  return X;
}

Ray Camera::GenerateRaySlow(float u, float v) const {
  const Eigen::Vector2d xy = Unproject(u, v);
  Ray r;
  if (!motion_.moving()) {
    r.o = o_W_;
    r.d = static_cast<float>(xy.x()) * ex_W_ + static_cast<float>(xy.y()) * ey_W_ + ez_W_;
    return r;
  }
  const Pose X = PoseAtRow(v);
  r.o = X.translation().cast<float>();
  r.d = (X.linear() * Eigen::Vector3d(xy.x(), xy.y(), 1.0)).cast<float>();
  return r;
}

bool Camera::Project(const Eigen::Vector3d& p_W, Eigen::Vector2d* uv, double* z) const {
  const Eigen::Vector3d p_O = X_WO_.inverse() * p_W;
  if (!(p_O.z() > 0)) return false;
  double xd = p_O.x() / p_O.z(), yd = p_O.y() / p_O.z();
  if (intrinsics_.has_distortion()) DistortNormalized(intrinsics_, xd, yd, &xd, &yd);
  *uv = Eigen::Vector2d(intrinsics_.fx * xd + intrinsics_.cx, intrinsics_.fy * yd + intrinsics_.cy);
  *z = p_O.z();
  return true;
}

}  // namespace penumbra
