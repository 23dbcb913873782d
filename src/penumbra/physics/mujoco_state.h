#pragma once
// internal to the physics module (includes mujoco.h): where each field of the state table
// (scene/sim_state.h kStateFields) lives in MuJoCo's mjData and how big it is for a model, the
// only two places that name MuJoCo's state arrays (MuJoCo 3's mj_stateElemPtr / mj_stateSize).

#include <mujoco/mujoco.h>

#include <cstdint>

#include "penumbra/scene/sim_state.h"

namespace penumbra {

/// the mjData array that holds `field` (StateFieldSize(field, MujocoStateDims(m, ...))
/// entries), or nullptr for a field that is not MuJoCo's (StateFieldInfo::mujoco false:
/// controller_next_update).
mjtNum* MujocoStatePtr(mjData* d, StateField field);
const mjtNum* MujocoStatePtr(const mjData* d, StateField field);

/// the state sizes of model `m` driven by `num_controllers` controllers.
StateDims MujocoStateDims(const mjModel* m, int64_t num_controllers);

}  // namespace penumbra
