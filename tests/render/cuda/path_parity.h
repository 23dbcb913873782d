#pragma once
// the pathtraced tier's parity metric (host: path_host_test.cc; GPU: path_gpu_test.cc) and the
// settings both backends render with.

#include <algorithm>
#include <cmath>
#include <vector>

#include "penumbra/core/image.h"
#include "penumbra/render/render_settings.h"
#include "penumbra/render/renderer.h"
#include "penumbra/scene/scene_description.h"

namespace penumbra::path_parity {

/// pathtraced settings for a parity frame: `spp` samples per pixel, 4 bounces, no denoiser (the
/// radiance is compared as the paths left it), the given backend.
inline RenderSettings PathSettings(RenderSettings::Backend backend, int spp) {
  RenderSettings s;
  s.backend = backend;
  s.tier = RenderSettings::Tier::kPathtraced;
  s.samples_per_pixel = spp;
  s.max_bounces = 4;
  s.denoise = false;
  return s;
}

/// `scene` with the default room's lamp diffusers glowing (material "room/lamp_diffuser" at
/// emission (2000, 1900, 1700) cd/m^2): emissive cylinders, so that the path samples emitters.
/// false if the scene has no such material.
inline bool MakeDiffusersEmissive(SceneDescription* scene) {
  for (Material& m : scene->materials) {
    if (m.name != "room/lamp_diffuser") continue;
    m.emission = Eigen::Vector3f(2000, 1900, 1700);
    return true;
  }
  return false;
}

/// `view` with lens distortion (k1 -0.28, k2 0.07, p1 0.002) and a rolling shutter over a
/// camera that moves 0.15 m sideways and turns 4 degrees about its vertical axis within the
/// frame: the camera the CPU's Camera::GenerateRay undistorts and poses per row exactly, and the
/// GPU's path traces from its ray tables (JitteredCameraRay).
inline void DistortAndMove(CameraView* view) {
  view->intrinsics.k1 = -0.28;
  view->intrinsics.k2 = 0.07;
  view->intrinsics.p1 = 0.002;
  view->motion.end_sec = 0.03;
  view->motion.time_sec = 0.0;
  view->motion.line_time_sec = 0.03 / view->intrinsics.height;
  view->motion.X_WO_end = view->X_WO;
  view->motion.X_WO_end.translation() += view->X_WO.linear() * Eigen::Vector3d(0.15, 0, 0);
  view->motion.X_WO_end.linear() =
      view->X_WO.linear() *
      Eigen::AngleAxisd(4.0 * M_PI / 180.0, Eigen::Vector3d::UnitY()).matrix();
}

/// the mean relative difference of two radiance images (H x W x 3) of one size, at the scale of
/// `tile` x `tile` pixel blocks: sum over blocks and channels of |sum got - sum want| over the sum
/// of want (so a per-pixel Monte Carlo noise that averages out within a block does not count,
/// a missing light does). 1 for images of different sizes or a black `want`.
inline double TileRelativeDifference(const ImageF& got, const ImageF& want, int tile = 8) {
  if (got.width != want.width || got.height != want.height || got.channels != 3 ||
      want.channels != 3 || want.data.empty())
    return 1;
  const int tx = (want.width + tile - 1) / tile, ty = (want.height + tile - 1) / tile;
  std::vector<double> g(static_cast<size_t>(tx) * ty * 3, 0.0), w(g.size(), 0.0);
  for (int v = 0; v < want.height; ++v)
    for (int u = 0; u < want.width; ++u)
      for (int k = 0; k < 3; ++k) {
        const size_t b = (static_cast<size_t>(v / tile) * tx + u / tile) * 3 + k;
        const size_t i = (static_cast<size_t>(v) * want.width + u) * 3 + k;
        g[b] += got.data[i];
        w[b] += want.data[i];
      }
  double diff = 0, total = 0;
  for (size_t b = 0; b < g.size(); ++b) {
    diff += std::abs(g[b] - w[b]);
    total += std::abs(w[b]);
  }
  return total > 0 ? diff / total : 1;
}

/// the relative difference of the two images' means, the largest over the channels.
inline double MeanRelativeDifference(const ImageF& got, const ImageF& want) {
  if (got.data.size() != want.data.size() || want.data.empty()) return 1;
  double worst = 0;
  for (int k = 0; k < 3; ++k) {
    double g = 0, w = 0;
    for (size_t i = k; i < want.data.size(); i += 3) g += got.data[i], w += want.data[i];
    worst = std::max(worst, w > 0 ? std::abs(g - w) / w : 1.0);
  }
  return worst;
}

}  // namespace penumbra::path_parity
