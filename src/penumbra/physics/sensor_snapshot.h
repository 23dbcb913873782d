#pragma once
// internal to the physics module (includes mujoco.h): the sensor and ground-truth part of
// Simulation::Snapshot.

#include <mujoco/mujoco.h>

#include "penumbra/scene/world_snapshot.h"

namespace penumbra {

/// copies everything mj_forward reads (time and every MuJoCo field of the state table,
/// scene/sim_state.h) from `live` into the scratch `scratch`.
void CopyStateForForward(const mjModel* m, const mjData* live, mjData* scratch);

/// fills out->sensordata, out->V_WB and out->contacts from `d` after mj_forward.
void FillSensorGroundTruth(const mjModel* m, const mjData* d, WorldSnapshot* out);

}  // namespace penumbra
