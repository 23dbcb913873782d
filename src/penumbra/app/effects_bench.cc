#include "penumbra/app/effects_bench.h"

#include <fmt/format.h>

#include <chrono>

#include "penumbra/app/preset_scene.h"

namespace penumbra {

void BenchRenderAdversity(const RenderBenchOptions& options) {
  WorldConfig world =
      LoadWorldFile(options.world_file.empty() ? DefaultWorldPath() : options.world_file);
  world.render.threads = options.threads;
  world.render.tier = options.tier == "pathtraced" ? RenderSettings::Tier::kPathtraced
                                                   : RenderSettings::Tier::kRealtime;
  fmt::print("adversity presets (worlds/adversity/presets.yaml), 640x480 rgb+depth {}:\n",
             options.tier);
  for (const char* preset : {"none", "minor", "major"}) {
    PresetScene p = LoadPresetScene(world, preset);
    p.StepTo(1.0);
    double render_sec = 0, effects_sec = 0;
    int64_t rays = 0;
    for (int i = 0; i < options.warmup_frames + options.frames; ++i) {
      p.StepTo(p.sim->time() + 1.0 / 30.0);
      double eff = 0;
      const auto t0 = std::chrono::steady_clock::now();
      const RenderedFrame f = p.Render(0, 640, 480, &eff);
      const double dt =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      if (i >= options.warmup_frames) {
        render_sec += dt - eff;
        effects_sec += eff;
        rays += f.rays;
      }
    }
    fmt::print(
        "  {:<6} {:.1f} frames/s, {:.2f} ms/frame, {:.1f} Mrays/s; effects evaluation "
        "{:.2f} ms/frame ({} effects, {} agents)\n",
        preset, options.frames / render_sec, 1e3 * render_sec / options.frames,
        rays / render_sec * 1e-6, 1e3 * effects_sec / options.frames, p.effects->effects().size(),
        p.effects->agents().size());
  }
  fmt::print("target (2-core CI machine): major >= 10 frames/s at 640x480 realtime\n");
}

}  // namespace penumbra
