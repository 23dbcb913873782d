#include "penumbra/bench/effects_bench.h"

#include <fmt/format.h>

#include <algorithm>
#include <string>

#include "penumbra/bench/preset_scene.h"
#include "penumbra/world/default_world.h"

namespace penumbra {

void BenchRenderAdversity(const RenderBenchOptions& options) {
  WorldConfig world =
      LoadWorldFile(options.world_file.empty() ? DefaultWorldPath() : options.world_file);
  world.render.threads = options.threads;
  world.render.tier = options.tier == "pathtraced" ? RenderSettings::Tier::kPathtraced
                                                   : RenderSettings::Tier::kRealtime;
  fmt::print("adversity presets (worlds/adversity/presets.yaml), 640x480 rgb+depth {}:\n",
             options.tier);
  double major_fps = 0;
  bool timed_major = false;
  for (const char* preset : {"none", "minor", "major"}) {
    if (!options.presets.empty() &&
        std::find(options.presets.begin(), options.presets.end(), preset) == options.presets.end())
      continue;
    PresetScene p = LoadPresetScene(world, preset);
    p.StepTo(1.0);
    RenderTiming sum;
    int64_t rays = 0;
    for (int i = 0; i < options.warmup_frames + options.frames; ++i) {
      p.StepTo(p.session->sim().time() + 1.0 / 30.0);
      RenderTiming t;
      const RenderedFrame f = p.Render(0, 640, 480, &t);
      if (i >= options.warmup_frames) {
        sum.render_wall += t.render_wall;
        sum.render_cpu += t.render_cpu;
        sum.effects_wall += t.effects_wall;
        rays += f.rays;
      }
    }
    const double n = options.frames;
    fmt::print(
        "  {:<6} {:.1f} frames/s, {:.2f} ms/frame, {:.1f} Mrays/s; CPU {:.1f} ms/frame "
        "(= {:.1f} frames/s on 2 idle cores); effects evaluation {:.2f} ms/frame "
        "({} effects, {} agents)\n",
        preset, n / sum.render_wall, 1e3 * sum.render_wall / n, rays / sum.render_wall * 1e-6,
        1e3 * sum.render_cpu / n, 2.0 * n / sum.render_cpu, 1e3 * sum.effects_wall / n,
        p.session->effects().effects().size(), p.session->effects().agents().size());
    if (std::string(preset) == "major") {
      major_fps = n / sum.render_wall;
      timed_major = true;
    }
  }
  if (timed_major) PrintRealtimeFpsTarget("major ", kMajorPresetTargetFps, major_fps, options.tier);
}

}  // namespace penumbra
