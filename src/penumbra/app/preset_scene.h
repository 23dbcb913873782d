#pragma once
// a world loaded with an adversity preset for single-frame work (contact sheet, bench
// render): composed models + agents, simulation with controllers and agent drivers, the
// renderer's scene and the effects stage (app/effects_stage.h), without a full run.

#include <memory>
#include <string>

#include "penumbra/app/effects_stage.h"
#include "penumbra/physics/simulation.h"
#include "penumbra/render/renderer.h"
#include "penumbra/world/world_config.h"

namespace penumbra {

/// wall-clock and process CPU time (all threads) of one PresetScene::Render, s.
struct RenderTiming {
  double effects_wall = 0, effects_cpu = 0;  ///< EffectsStage::Evaluate
  double render_wall = 0, render_cpu = 0;    ///< Renderer::Render
};

/// everything needed to step a world and render its cameras with effects.
struct PresetScene {
  std::unique_ptr<EffectsStage> effects;
  std::unique_ptr<Simulation> sim;
  SceneDescription scene;
  std::unique_ptr<Renderer> renderer;

  /// steps the simulation until its time is >= t_sec (never backwards).
  void StepTo(double t_sec);
  /// renders scene camera `camera` (its intrinsics unless width/height > 0, then the same
  /// vertical field of view at that size) at the current time, effects included.
  /// @param timing if not null, receives the times of the effects and of the render
  RenderedFrame Render(int camera, int width = 0, int height = 0, RenderTiming* timing = nullptr);
};

/// loads `world` with the preset spec `adversity` ("" = the world's own).
/// @throws ConfigError for bad input (as RunWorld).
PresetScene LoadPresetScene(const WorldConfig& world, const std::string& adversity);

}  // namespace penumbra
