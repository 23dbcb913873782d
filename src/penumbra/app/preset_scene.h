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
  /// @param effects_sec if not null, receives the time spent evaluating effects (s)
  RenderedFrame Render(int camera, int width = 0, int height = 0, double* effects_sec = nullptr);
};

/// loads `world` with the preset spec `adversity` ("" = the world's own).
/// @throws ConfigError for bad input (as RunWorld).
PresetScene LoadPresetScene(const WorldConfig& world, const std::string& adversity);

}  // namespace penumbra
