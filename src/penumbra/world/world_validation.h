#pragma once
// semantic checks of a WorldConfig (ranges, required values, unique names, files
// that must exist, cross-field rules). shared by ParseWorld, which knows the line
// of every key, and WorldConfig::ValidateOrThrow, which does not.

#include <string>

#include "penumbra/config/param_reader.h"
#include "penumbra/world/world_config.h"

namespace penumbra {

/// checks every rule of the world-file reference (docs/world-file.md).
/// key paths are those of the world file ("lights[2].intensity_cd"); the models of
/// `world.models` map back to `robots[i]` / `models[j]` by their is_robot flag.
/// @throws ConfigError(world.file, lines.Find(key path), key path, problem) on the
///         first violation.
void ValidateWorld(const WorldConfig& world, const LineTable& lines);

/// true if `name` is non-empty and only has the characters [A-Za-z0-9_-].
bool IsValidWorldName(const std::string& name);

}  // namespace penumbra
