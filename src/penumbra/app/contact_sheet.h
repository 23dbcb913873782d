#pragma once
// `penumbra contact-sheet`: the same instant of a world rendered under several adversity
// presets, side by side with the preset names above, as one PNG (docs/effects.png); several
// worlds give one row each (docs/environments.png).

#include <optional>
#include <string>
#include <vector>

#include "penumbra/render/render_settings.h"

namespace penumbra {

/// options of `penumbra contact-sheet`.
struct ContactSheetOptions {
  /// one row per world file, top down; empty = the bundled default world.
  std::vector<std::string> worlds;
  std::vector<std::string> presets = {"none", "minor", "major"};
  double time_sec = 1.0;          ///< sim time of the frames
  int width = 640, height = 480;  ///< size of each frame (the world camera's field of view)
  std::string out = "docs/effects.png";
  int threads = 0;  ///< render threads, 0 = all cores
  /// --backend; nullopt = each world's render.backend.
  std::optional<RenderSettings::Backend> backend;
};

/// renders each world's first camera at time_sec under every preset and writes the sheet: one
/// row per world, (rows (height + 28) + (rows - 1) 8) x (n width + (n - 1) 8) x 3 sRGB. returns 0.
/// @throws ConfigError for an unknown world or preset.
int MakeContactSheet(const ContactSheetOptions& options);

}  // namespace penumbra
