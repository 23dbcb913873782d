#pragma once
// internal to the physics module (includes mujoco.h): where each field of the state table
// (scene/sim_state.h kStateFields) lives in MuJoCo's mjData and how big it is for a model, the
// only two places that name MuJoCo's state arrays (MuJoCo's mj_stateElemPtr / mj_stateSize),
// and the copies between a SimState's vectors and mjData built on them.

#include <mujoco/mujoco.h>

#include <cstdint>
#include <span>

#include "penumbra/scene/sim_state.h"

namespace penumbra {

/// where a field lives in mjData: an mjtNum array (`num`) or, for a flag field
/// (StateFieldInfo::flag: eq_active), an mjtBool array (`flag`); both null for a field that is
/// not MuJoCo's (StateFieldInfo::mujoco false: controller_next_update).
struct MujocoStateArray {
  mjtNum* num = nullptr;
  mjtBool* flag = nullptr;
};

/// the mjData array of `field` (StateFieldSize(field, MujocoStateDims(m, ...)) entries).
MujocoStateArray MujocoStateArrayOf(mjData* d, StateField field);

/// copies `field` of `d` into `out` (its size entries): mjtNum bit for bit, mjtBool as 0 or 1.
void ReadMujocoState(const mjData* d, StateField field, std::span<double> out);
/// copies `in` into `field` of `d` (its size entries): mjtNum bit for bit, a flag as in != 0
/// (SetState checks flags are 0 or 1 first: StateMismatch).
void WriteMujocoState(mjData* d, StateField field, std::span<const double> in);
/// copies `n` entries of `field` from `src` to `dst` (two mjData of the same model).
void CopyMujocoState(const mjData* src, mjData* dst, StateField field, int64_t n);

/// the state sizes of model `m` driven by `num_controllers` controllers.
StateDims MujocoStateDims(const mjModel* m, int64_t num_controllers);

}  // namespace penumbra
