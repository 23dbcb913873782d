#include "penumbra/app/preset_scene.h"

#include <chrono>
#include <cmath>
#include <ctime>

#include "penumbra/session/scene_assembly.h"
#include "penumbra/compose/scene_composer.h"
#include "penumbra/control/controller_factory.h"
#include "penumbra/core/error.h"
#include "penumbra/physics/urdf_converter.h"

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

PresetScene LoadPresetScene(const WorldConfig& world_in, const std::string& adversity) {
  WorldConfig world = world_in;
  world.render.seed = world.seed;
  ComposeOptions compose_options;
  compose_options.urdf_to_mjcf = ConvertUrdfToMjcf;
  compose_options.timestep_sec = world.timestep_sec;
  ComposedScene composed = ComposeWorld(world.models, compose_options);
  PresetScene p;
  p.effects = std::make_unique<EffectsStage>(world, &composed, adversity);
  p.sim = std::make_unique<Simulation>(
      Simulation::LoadFromString(composed.mjcf_xml, world.timestep_sec));
  for (const ModelConfig& m : world.models)
    if (m.is_robot && !m.controller.type.empty())
      p.sim->AddController(MakeController(m.controller, m.name, world.file));
  p.effects->Attach(p.sim.get());
  p.scene = p.effects->Bind(AssembleScene(p.sim->scene(), world, p.sim->Snapshot()));
  if (p.scene.cameras.empty())
    throw ConfigError(world.file, 0, "cameras", "the world has no camera");
  p.renderer = MakeEmbreeRenderer(p.scene, world.render);
  return p;
}

void PresetScene::StepTo(double t_sec) {
  while (sim->time() < t_sec - 1e-9) sim->Step();
}

RenderedFrame PresetScene::Render(int camera, int width, int height, RenderTiming* timing) {
  const CameraSpec& cam = scene.cameras.at(camera);
  const WorldSnapshot snap = sim->Snapshot();
  CameraView view;
  view.X_WO = CameraPoseInWorld(cam, snap);
  view.intrinsics = cam.intrinsics;
  if (width > 0 && height > 0) {
    const double fovy_deg =
        2.0 * std::atan(0.5 * cam.intrinsics.height / cam.intrinsics.fy) * 180.0 / M_PI;
    view.intrinsics = CameraIntrinsics::FromFovy(width, height, fovy_deg);
  }
  view.outputs.rgb = true;
  view.outputs.depth = true;
  view.exposure_time_sec = cam.exposure_time_sec;
  view.near_m = cam.near_m;
  view.frame_index = snap.step;
  view.camera_index = camera;
  RenderTiming t;
  double w0 = WallSeconds(), c0 = CpuSeconds();
  const std::shared_ptr<const EffectsFrame> fx = effects->Evaluate(snap, view.X_WO.translation());
  double w1 = WallSeconds(), c1 = CpuSeconds();
  t.effects_wall = w1 - w0;
  t.effects_cpu = c1 - c0;
  RenderedFrame frame;
  renderer->Render(snap, fx.get(), view, &frame);
  t.render_wall = WallSeconds() - w1;
  t.render_cpu = CpuSeconds() - c1;
  if (timing) *timing = t;
  return frame;
}

}  // namespace penumbra
