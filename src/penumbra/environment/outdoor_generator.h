#pragma once
// worlds/outdoor.yaml's terrain (docs/environments.md "outdoor"): 60 x 60 m of rolling ground
// as a MuJoCo height field (0.25 m samples) with a trail flattened through it, trees, rocks,
// bushes and a roofed shelter over the trail; the ground's relief, trees, rocks, bushes and the
// materials' seeds are chosen by the seed.

#include <cstdint>

#include "penumbra/environment/environment_generator.h"

namespace penumbra {

/// the outdoor terrain of `seed` with procedural maps of `texture_resolution` texels per side.
GeneratedEnvironment GenerateOutdoor(uint64_t seed, int texture_resolution);

}  // namespace penumbra
