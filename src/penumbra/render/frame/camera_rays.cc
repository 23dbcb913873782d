#include "penumbra/render/frame/camera_rays.h"

namespace penumbra::cuda {

bool SameIntrinsics(const CameraIntrinsics& a, const CameraIntrinsics& b) {
  return a.width == b.width && a.height == b.height && a.fx == b.fx && a.fy == b.fy &&
         a.cx == b.cx && a.cy == b.cy && a.k1 == b.k1 && a.k2 == b.k2 && a.p1 == b.p1 &&
         a.p2 == b.p2 && a.k3 == b.k3;
}

void CameraRayTables::Prepare(const CameraView& view, ThreadPool* pool) {
  const Camera camera(view.X_WO, view.intrinsics, view.motion);
  const int W = camera.width(), H = camera.height();
  if (!view.intrinsics.has_distortion()) {
    if (!xy_.empty()) ++xy_version_;
    xy_.clear();
  } else if (xy_.empty() || !SameIntrinsics(view.intrinsics, xy_intrinsics_)) {
    // Camera::GenerateRay's coordinates, cast to float as it casts them
    xy_.assign(static_cast<size_t>(W) * H * 2, 0.0f);
    ParallelForOrSerial(pool, H, [&](int64_t v) {
      for (int u = 0; u < W; ++u) {
        const Eigen::Vector2d p = camera.Unproject(u, static_cast<double>(v));
        float* out = &xy_[2 * (static_cast<size_t>(v) * W + u)];
        out[0] = static_cast<float>(p.x());
        out[1] = static_cast<float>(p.y());
      }
    });
    xy_intrinsics_ = view.intrinsics;
    ++xy_version_;
  }
  rows_.clear();
  if (!view.motion.moving()) return;
  rows_.resize(static_cast<size_t>(H) * 12);
  for (int v = 0; v < H; ++v) {
    const Pose X = camera.PoseAtRow(v);
    float* r = &rows_[12 * static_cast<size_t>(v)];
    for (int k = 0; k < 3; ++k) {
      r[k] = static_cast<float>(X.translation()(k));
      r[3 + k] = static_cast<float>(X.linear()(k, 0));
      r[6 + k] = static_cast<float>(X.linear()(k, 1));
      r[9 + k] = static_cast<float>(X.linear()(k, 2));
    }
  }
}

}  // namespace penumbra::cuda
