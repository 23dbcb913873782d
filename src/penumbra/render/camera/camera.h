#pragma once
// camera rays in the OpenCV convention: pixel centres at integer coordinates, optical frame
// x right, y down, z forward. the ray through pixel (u, v) has optical-frame direction
// (x, y, 1), where (x, y) are the undistorted normalised coordinates of the pixel: for a
// pinhole (x, y) = ((u - cx) / fx, (v - cy) / fy); with Brown-Conrady distortion
// (CameraIntrinsics k1 k2 p1 p2 k3, render/camera/camera_distortion.h) (x, y) is the exact Newton
// inverse of the distortion map, so a hit at ray parameter t lies at z-depth t along the
// optical axis (depth images are z, range is t |d|).
//
// motion (CameraMotion): the optical frame may move during the exposure. the pose at time s
// after the frame's time is interpolated between X_WO (s = 0) and X_WO_end (s = end_sec):
// position linearly, rotation by quaternion slerp. a pixel in row v is seen at time
// s = time_sec + line_time_sec * v (rolling shutter: rows are read out top to bottom; a
// global shutter has line_time_sec = 0). motion blur over the exposure is made by rendering
// sub-frames at several time_sec and averaging them (sensors/camera_imager.h).

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "penumbra/core/pose.h"
#include "penumbra/render/ray.h"
#include "penumbra/scene/scene_description.h"

namespace penumbra {

/// motion of the optical frame around one frame (see the file comment).
struct CameraMotion {
  Pose X_WO_end = Pose::Identity();  ///< optical frame in the world at time end_sec
  double end_sec = 0;                ///< time of X_WO_end after the frame's time, s; 0 = no motion
  double time_sec = 0;               ///< time at which row 0 is seen, s after the frame's time
  double line_time_sec = 0;  ///< rolling shutter: delay between consecutive rows, s (0 = global)

  /// true if rays depend on time (the camera moves between X_WO and X_WO_end).
  bool moving() const { return end_sec > 0; }
};

/// a posed camera. immutable, thread-safe.
class Camera {
 public:
  /// @param X_WO  pose of the optical frame in the world at the frame's time
  /// @throws ConfigError (key "camera.intrinsics") if width/height < 1, fx/fy are not positive
  ///         and finite, or the distortion folds the image (see FindDistortionProblem);
  ///         ConfigError (key "camera.motion") for a negative or non-finite motion time.
  Camera(const Pose& X_WO, const CameraIntrinsics& intrinsics, const CameraMotion& motion = {});

  /// world ray through pixel coordinates (u, v) (column, row; pixel centres are integers).
  /// the origin is the optical centre (at the row's time); d has optical-frame z = 1
  /// (t = z-depth).
  Ray GenerateRay(float u, float v) const {
    if (slow_) return GenerateRaySlow(u, v);
    const float x = (u - cx_) * inv_fx_;
    const float y = (v - cy_) * inv_fy_;
    Ray r;
    r.o = o_W_;
    r.d = x * ex_W_ + y * ey_W_ + ez_W_;
    return r;
  }

  /// undistorted normalised coordinates (x, y) of pixel (u, v) (the optical-frame ray
  /// direction is (x, y, 1)); exact to 1e-12 with distortion.
  Eigen::Vector2d Unproject(double u, double v) const;

  /// optical frame in the world at the time row v is seen (X_WO when the camera does not move).
  Pose PoseAtRow(double v) const;

  /// projects world point p_W (with the frame pose X_WO and the distortion): pixel
  /// coordinates (u, v) and z-depth in the optical frame. returns false (outputs untouched)
  /// for points at or behind the camera plane (z <= 0).
  bool Project(const Eigen::Vector3d& p_W, Eigen::Vector2d* uv, double* z) const;

  /// true for a pinhole without distortion or motion: every ray starts at the optical centre
  /// and its direction is an affine function of (u, v), so the rays of a pixel rectangle lie
  /// in the convex cone of its corner rays.
  bool projective() const { return !slow_; }

  /// the spread angle of one pixel's cone of rays, rad: 1 / sqrt(fx fy), a pixel's angular
  /// size at the principal point (the ray-cone texture level of detail,
  /// render/material/material_eval.h; off-axis pixels and lens distortion change it, which the cone
  /// ignores).
  float pixel_spread_rad() const { return pixel_spread_rad_; }

  /// the terms of GenerateRay for a projective() camera: the ray through pixel (u, v) is
  /// o_W + t (((u - cx) inv_fx) ex_W + ((v - cy) inv_fy) ey_W + ez_W) (ex, ey, ez: the optical
  /// axes in the world). the CUDA backend's primary rays take them (render/cuda/).
  struct PinholeTerms {
    Eigen::Vector3f o_W, ex_W, ey_W, ez_W;
    float cx, cy, inv_fx, inv_fy;
  };
  PinholeTerms pinhole_terms() const {
    return {o_W_, ex_W_, ey_W_, ez_W_, cx_, cy_, inv_fx_, inv_fy_};
  }

  int width() const { return intrinsics_.width; }
  int height() const { return intrinsics_.height; }
  const CameraIntrinsics& intrinsics() const { return intrinsics_; }
  const Pose& X_WO() const { return X_WO_; }
  const CameraMotion& motion() const { return motion_; }

 private:
  Ray GenerateRaySlow(float u, float v) const;

  Pose X_WO_;
  CameraIntrinsics intrinsics_;
  CameraMotion motion_;
  bool slow_ = false;                         // distortion or motion
  Eigen::Vector3f o_W_, ex_W_, ey_W_, ez_W_;  // optical centre and optical axes in the world
  float cx_, cy_, inv_fx_, inv_fy_;
  float pixel_spread_rad_ = 0;
  Eigen::Quaterniond q0_, q1_;  // rotations at s = 0 and s = end_sec
};

}  // namespace penumbra
