#pragma once
// helpers of the realtime rgb parity tests (host: realtime_host_test.cc; GPU:
// realtime_rgb_gpu_test.cc): a bundled world after 1 s of simulation, its first camera's view,
// and the image comparisons (rgb PSNR, depth within 1 mm).

#include <cmath>
#include <cstdint>
#include <memory>
#include <string>

#include "penumbra/physics/simulation.h"
#include "penumbra/render/renderer.h"
#include "penumbra/scene/camera_pose.h"
#include "penumbra/session/session.h"
#include "penumbra/world/world_config.h"

namespace penumbra::realtime_parity {

/// bundled world `name` (worlds/<name>) after `t_sec` of simulation, without its renderer.
inline std::unique_ptr<Session> LoadSimulatedAt(const std::string& name, double t_sec) {
  SessionOptions so;
  so.build_renderer = false;
  so.add_controllers = false;
  auto session = std::make_unique<Session>(
      LoadWorldFile(std::string(PENUMBRA_SOURCE_DIR) + "/worlds/" + name), so);
  while (session->sim().time() < t_sec) session->sim().Step();
  return session;
}

/// bundled world `name` (worlds/<name>) after 1 s of simulation, without its renderer.
inline std::unique_ptr<Session> LoadSimulated(const std::string& name) {
  return LoadSimulatedAt(name, 1.0);
}

/// camera `camera` (default the first) of `scene` at w x h (its vertical field of view), rgb and
/// depth. @throws std::out_of_range if the scene has no such camera.
inline CameraView RgbDepthView(const SceneDescription& scene, const WorldSnapshot& snap, int w,
                               int h, int camera = 0) {
  const CameraSpec& cam = scene.cameras.at(camera);
  CameraView view;
  view.X_WO = CameraPoseInWorld(cam, snap);
  const double fovy_deg = cam.intrinsics.fovy_deg();
  view.intrinsics = CameraIntrinsics::FromFovy(w, h, fovy_deg);
  view.near_m = cam.near_m;
  view.outputs[ImageKind::kRgb] = true;
  view.outputs[ImageKind::kDepth] = true;
  view.outputs[ImageKind::kSegmentation] = false;
  return view;
}

/// a bundled world's frame as the parity tests render it: the world after `t_sec` of
/// simulation, its snapshot, a camera's rgb+depth view and the effects at that camera.
struct WorldFrame {
  std::unique_ptr<Session> session;
  WorldSnapshot snap;
  CameraView view;
  std::shared_ptr<const EffectsFrame> fx;  ///< the world's effects at the camera, or null
};

/// bundled world `name` after `t_sec` of simulation, camera `camera` at w x h (RgbDepthView) and
/// its effects frame (EffectsStage::Evaluate at the camera's position).
inline WorldFrame LoadFrameAt(const std::string& name, double t_sec, int w, int h, int camera = 0) {
  WorldFrame f;
  f.session = LoadSimulatedAt(name, t_sec);
  f.snap = f.session->sim().Snapshot();
  f.view = RgbDepthView(f.session->scene(), f.snap, w, h, camera);
  f.fx = f.session->effects().Evaluate(f.snap, f.view.X_WO.translation());
  return f;
}

/// gives *view a rolling shutter over a moving camera: rows read out over 30 ms while the camera
/// moves by (0.15, 0.05, 0) m and turns by 0.25 rad about the world's z axis (camera.h's
/// CameraMotion; the pose X_WO at the first row).
inline void AddRollingShutter(CameraView* view) {
  view->motion.end_sec = 0.03;
  view->motion.line_time_sec = 0.03 / view->intrinsics.height;
  view->motion.X_WO_end = view->X_WO;
  view->motion.X_WO_end.translation() += Eigen::Vector3d(0.15, 0.05, 0);
  view->motion.X_WO_end.linear() =
      Eigen::AngleAxisd(0.25, Eigen::Vector3d::UnitZ()).toRotationMatrix() * view->X_WO.linear();
}

/// adds two homogeneous media to *fx (rain in fog, for the culling tests): a height fog
/// over the whole world (sigma_t 0.3 / 0.35 / 0.4 per m below z = 0, falling off by 0.2 per m
/// above) and a haze in the 20 m box around the world's origin (0.2 per m), so rain streaks a
/// few metres away are culled as invisible (kRainCullContrast).
inline void AddRainFog(EffectsFrame* fx) {
  HomogeneousMedium fog;
  fog.sigma_t_per_m = Eigen::Vector3f(0.3f, 0.35f, 0.4f);
  fog.height_falloff_per_m = 0.2f;
  fx->homogeneous_media.push_back(fog);
  HomogeneousMedium haze;
  haze.sigma_t_per_m = Eigen::Vector3f(0.2f, 0.2f, 0.2f);
  haze.region = BoxRegion{Eigen::Vector3d(-10, -10, -10), Eigen::Vector3d(10, 10, 10)};
  fx->homogeneous_media.push_back(haze);
}

/// PSNR (dB) of two 8-bit images of one size: 10 log10(255^2 / MSE); 99 when equal.
inline double Psnr(const ImageU8& a, const ImageU8& b) {
  if (a.data.size() != b.data.size() || a.data.empty()) return 0;
  double se = 0;
  for (size_t i = 0; i < a.data.size(); ++i) {
    const double d = static_cast<double>(a.data[i]) - static_cast<double>(b.data[i]);
    se += d * d;
  }
  if (se == 0) return 99;
  return 10.0 * std::log10(255.0 * 255.0 / (se / static_cast<double>(a.data.size())));
}

/// the fraction of pixels whose depths differ by more than 1 mm.
inline double DepthMismatch(const ImageF& a, const ImageF& b) {
  if (a.data.size() != b.data.size() || a.data.empty()) return 1;
  int64_t bad = 0;
  for (size_t i = 0; i < a.data.size(); ++i) bad += std::abs(a.data[i] - b.data[i]) > 1e-3f;
  return static_cast<double>(bad) / static_cast<double>(a.data.size());
}

}  // namespace penumbra::realtime_parity
