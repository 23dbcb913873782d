#include "penumbra/physics/mujoco_state.h"

namespace penumbra {

const mjtNum* MujocoStatePtr(const mjData* d, StateField field) {
  switch (field) {
    case StateField::kQpos:
      return d->qpos;
    case StateField::kQvel:
      return d->qvel;
    case StateField::kAct:
      return d->act;
    case StateField::kCtrl:
      return d->ctrl;
    case StateField::kQaccWarmstart:
      return d->qacc_warmstart;
    case StateField::kQfrcApplied:
      return d->qfrc_applied;
    case StateField::kXfrcApplied:
      return d->xfrc_applied;
    case StateField::kMocapPos:
      return d->mocap_pos;
    case StateField::kMocapQuat:
      return d->mocap_quat;
    case StateField::kUserdata:
      return d->userdata;
    case StateField::kControllerNextUpdate:
      return nullptr;
  }
  return nullptr;
}

mjtNum* MujocoStatePtr(mjData* d, StateField field) {
  return const_cast<mjtNum*>(MujocoStatePtr(static_cast<const mjData*>(d), field));
}

StateDims MujocoStateDims(const mjModel* m, int64_t num_controllers) {
  StateDims dims;
  for (int i = 0; i < kNumStateDims; ++i) {
    const auto dim = static_cast<StateDim>(i);
    switch (dim) {
      case StateDim::kNq:
        dims[dim] = m->nq;
        break;
      case StateDim::kNv:
        dims[dim] = m->nv;
        break;
      case StateDim::kNa:
        dims[dim] = m->na;
        break;
      case StateDim::kNu:
        dims[dim] = m->nu;
        break;
      case StateDim::kNmocap:
        dims[dim] = m->nmocap;
        break;
      case StateDim::kNuserdata:
        dims[dim] = m->nuserdata;
        break;
      case StateDim::kNbody:
        dims[dim] = m->nbody;
        break;
      case StateDim::kNumControllers:
        dims[dim] = num_controllers;
        break;
    }
  }
  return dims;
}

}  // namespace penumbra
