#include "penumbra/bench/preset_scene.h"

#include <chrono>
#include <cmath>
#include <ctime>

#include "penumbra/core/error.h"
#include "penumbra/scene/camera_pose.h"

namespace penumbra {
namespace {

double CpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

double WallSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

PresetScene LoadPresetScene(const WorldConfig& world, const std::string& adversity) {
  SessionOptions options;
  options.adversity = adversity;
  PresetScene p;
  p.session = std::make_unique<Session>(world, options);
  if (p.session->scene().cameras.empty())
    throw ConfigError(world.file, 0, "cameras", "the world has no camera");
  return p;
}

void PresetScene::StepTo(double t_sec) {
  Simulation& sim = session->sim();
  while (sim.time() < t_sec - 1e-9) sim.Step();
}

RenderedFrame PresetScene::Render(int camera, int width, int height, RenderTiming* timing) {
  const CameraSpec& cam = session->scene().cameras.at(camera);
  const WorldSnapshot snap = session->sim().Snapshot();
  CameraView view;
  view.X_WO = CameraPoseInWorld(cam, snap);
  view.intrinsics = cam.intrinsics;
  if (width > 0 && height > 0) {
    const double fovy_deg = cam.intrinsics.fovy_deg();
    view.intrinsics = CameraIntrinsics::FromFovy(width, height, fovy_deg);
  }
  view.outputs[ImageKind::kRgb] = true;
  view.outputs[ImageKind::kDepth] = true;
  view.exposure_time_sec = cam.exposure_time_sec;
  view.near_m = cam.near_m;
  view.frame_index = snap.step;
  view.camera_index = camera;
  RenderTiming t;
  double w0 = WallSeconds(), c0 = CpuSeconds();
  const std::shared_ptr<const EffectsFrame> fx =
      session->effects().Evaluate(snap, view.X_WO.translation());
  double w1 = WallSeconds(), c1 = CpuSeconds();
  t.effects_wall = w1 - w0;
  t.effects_cpu = c1 - c0;
  RenderedFrame frame;
  session->renderer()->Render(snap, fx.get(), view, &frame);
  t.render_wall = WallSeconds() - w1;
  t.render_cpu = CpuSeconds() - c1;
  if (timing) *timing = t;
  return frame;
}

}  // namespace penumbra
