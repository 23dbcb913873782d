#pragma once
// worlds/house.yaml's building (docs/environments.md "house"): a one-storey house of 12 x 9 m,
// 2.7 m high, with a living room, a kitchen, a hallway, a bedroom and a study, doors and
// windows, ceiling lamps, furniture and clutter chosen by the seed.

#include <cstdint>

#include "penumbra/environment/environment_generator.h"

namespace penumbra {

/// the house of `seed` with procedural maps of `texture_resolution` texels per side.
GeneratedEnvironment GenerateHouse(uint64_t seed, int texture_resolution);

}  // namespace penumbra
