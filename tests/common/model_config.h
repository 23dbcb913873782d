#pragma once
// a world-file model entry for composer tests.

#include <string>

#include "penumbra/world/world_config.h"

namespace penumbra::testing {

/// a ModelConfig with only its name and model file (MJCF or URDF path) set.
inline ModelConfig Model(const std::string& name, const std::string& file) {
  ModelConfig m;
  m.name = name;
  m.file = file;
  return m;
}

}  // namespace penumbra::testing
