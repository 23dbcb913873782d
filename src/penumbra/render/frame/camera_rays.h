#pragma once
// the primary rays of a camera that is not a plain pinhole (lens distortion, a moving camera:
// rolling shutter), for the CUDA backend: tables the host computes with the CPU backend's own
// camera model (render/camera/camera.h: Camera::Unproject undistorts, Camera::PoseAtRow gives each
// row's pose) and PinholeCamera points to (PinholeCamera::xy, rows), so the kernels' PrimaryRay
// (realtime_shading.h) casts the ray Camera::GenerateRay casts: o + t (x ex + y ey + ez) with
// (x, y) the pixel's undistorted normalised coordinates and o, ex, ey, ez the optical centre
// and axes at the time its row is seen. plain C++ (no CUDA).

#include <cstdint>
#include <vector>

#include "penumbra/core/thread_pool.h"
#include "penumbra/render/camera/camera.h"
#include "penumbra/render/renderer.h"
#include "penumbra/render/transport/primary_pixel.h"

namespace penumbra::cuda {

/// true if a and b are the same camera model (size, fx fy cx cy, k1 k2 p1 p2 k3): their xy
/// tables are the same.
bool SameIntrinsics(const CameraIntrinsics& a, const CameraIntrinsics& b);

/// a camera's ray tables (see the file comment).
class CameraRayTables {
 public:
  /// fills the tables of `view`: xy when it has lens distortion (kept while the intrinsics stay
  /// the same), rows when it moves; a pinhole that does not move gets none.
  /// @throws ConfigError as Camera for bad intrinsics or motion.
  void Prepare(const CameraView& view, ThreadPool* pool);
  /// (H x W x 2) float: the undistorted normalised coordinates (x, y) of each pixel centre
  /// (Camera::Unproject), row-major; empty without distortion.
  const std::vector<float>& xy() const { return xy_; }
  /// (H x 12) float: each row's optical centre o_W (m) and axes ex_W, ey_W, ez_W (unit) at the
  /// time it is seen (Camera::PoseAtRow); empty when the camera does not move.
  const std::vector<float>& rows() const { return rows_; }
  /// counts the changes of xy() (a device copy must be refreshed when it differs).
  int64_t xy_version() const { return xy_version_; }
  /// `c` with its table pointers set to `xy` and `rows` where this camera has those tables
  /// (null where it has not): the host's own arrays for the host path, device copies for the
  /// kernels.
  PinholeCamera Point(PinholeCamera c, const float* xy, const float* rows) const {
    c.xy = xy_.empty() ? nullptr : xy;
    c.rows = rows_.empty() ? nullptr : rows;
    return c;
  }

 private:
  std::vector<float> xy_, rows_;
  CameraIntrinsics xy_intrinsics_;  // the intrinsics xy_ was computed for
  int64_t xy_version_ = 0;
};

}  // namespace penumbra::cuda
