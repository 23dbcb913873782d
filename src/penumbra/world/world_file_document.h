#pragma once
// a world file read again by a part that needs one block of it after the world was loaded
// (mesh import settings, procedural materials).

#include <optional>
#include <string>

#include "penumbra/config/config_value.h"

namespace penumbra {

/// the YAML tree of `world_file`; nullopt when the file cannot be read or parsed (a replay's
/// recorded world whose file is gone: the caller falls back to its defaults).
std::optional<ConfigValue> ReadWorldFileDocument(const std::string& world_file);

}  // namespace penumbra
