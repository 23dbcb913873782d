#pragma once
// a world loaded with an adversity preset for single-frame work (contact sheet, bench
// render): a Session (session/session.h: composed models + agents, simulation with
// controllers and agent drivers, the renderer's scene, the effects stage and the renderer),
// stepped and rendered one frame at a time, without a full run.

#include <memory>
#include <string>

#include "penumbra/render/renderer.h"
#include "penumbra/session/session.h"
#include "penumbra/world/world_config.h"

namespace penumbra {

/// wall-clock and process CPU time (all threads) of one PresetScene::Render, s.
struct RenderTiming {
  double effects_wall = 0, effects_cpu = 0;  ///< EffectsStage::Evaluate
  double render_wall = 0, render_cpu = 0;    ///< Renderer::Render
};

/// everything needed to step a world and render its cameras with effects.
struct PresetScene {
  /// the loaded world (never null after LoadPresetScene).
  std::unique_ptr<Session> session;

  /// steps the simulation until its time is >= t_sec (never backwards).
  void StepTo(double t_sec);
  /// renders scene camera `camera` (its intrinsics unless width/height > 0, then the same
  /// vertical field of view at that size) at the current time, effects included.
  /// @param timing if not null, receives the times of the effects and of the render
  RenderedFrame Render(int camera, int width = 0, int height = 0, RenderTiming* timing = nullptr);
};

/// loads `world` with the preset spec `adversity` ("" = the world's own).
/// @throws ConfigError for bad input (as RunWorld), and naming the key "cameras" when the
///         world has no camera.
PresetScene LoadPresetScene(const WorldConfig& world, const std::string& adversity);

}  // namespace penumbra
