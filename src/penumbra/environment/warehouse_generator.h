#pragma once
// worlds/warehouse.yaml's building (docs/environments.md "warehouse"): a hall of 30 x 20 m,
// 8 m high, with three rows of pallet racks, a staging area by four open dock doors, floor
// markings, high-bay lamps; rack occupancy, loads, staged pallets and materials chosen by the
// seed.

#include <cstdint>

#include "penumbra/environment/environment_generator.h"

namespace penumbra {

/// the warehouse of `seed` with procedural maps of `texture_resolution` texels per side.
GeneratedEnvironment GenerateWarehouse(uint64_t seed, int texture_resolution);

}  // namespace penumbra
