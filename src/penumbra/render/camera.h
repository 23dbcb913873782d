#pragma once
// pinhole camera rays in the OpenCV convention: pixel centres at integer coordinates,
// the ray through pixel (u, v) has direction ((u - cx) / fx, (v - cy) / fy, 1) in the
// optical frame (x right, y down, z forward), so a hit at ray parameter t lies at
// z-depth t along the optical axis (depth images are z, not range).

#include <Eigen/Core>

#include "penumbra/core/pose.h"
#include "penumbra/render/ray_scene.h"
#include "penumbra/scene/scene_description.h"

namespace penumbra {

/// a posed pinhole camera. immutable, thread-safe.
class Camera {
 public:
  /// @param X_WO  pose of the optical frame in the world
  /// @throws ConfigError if width/height < 1 or fx/fy are not positive and finite.
  Camera(const Pose& X_WO, const CameraIntrinsics& intrinsics);

  /// world ray through pixel coordinates (u, v) (column, row; pixel centres are integers).
  /// the origin is the optical centre; d has optical-frame z = 1 (t = z-depth).
  Ray GenerateRay(float u, float v) const {
    const float x = (u - cx_) * inv_fx_;
    const float y = (v - cy_) * inv_fy_;
    Ray r;
    r.o = o_W_;
    r.d = x * ex_W_ + y * ey_W_ + ez_W_;
    return r;
  }

  /// projects world point p_W: pixel coordinates (u, v) and z-depth in the optical frame.
  /// returns false (outputs untouched) for points at or behind the camera plane (z <= 0).
  bool Project(const Eigen::Vector3d& p_W, Eigen::Vector2d* uv, double* z) const;

  int width() const { return intrinsics_.width; }
  int height() const { return intrinsics_.height; }
  const CameraIntrinsics& intrinsics() const { return intrinsics_; }
  const Pose& X_WO() const { return X_WO_; }

 private:
  Pose X_WO_;
  CameraIntrinsics intrinsics_;
  Eigen::Vector3f o_W_, ex_W_, ey_W_, ez_W_;  // optical centre and optical axes in the world
  float cx_, cy_, inv_fx_, inv_fy_;
};

}  // namespace penumbra
