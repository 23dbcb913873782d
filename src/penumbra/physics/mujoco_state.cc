#include "penumbra/physics/mujoco_state.h"

#include <algorithm>
#include <cstring>

namespace penumbra {

MujocoStateArray MujocoStateArrayOf(mjData* d, StateField field) {
  switch (field) {
    case StateField::kQpos:
      return {d->qpos};
    case StateField::kQvel:
      return {d->qvel};
    case StateField::kAct:
      return {d->act};
    case StateField::kCtrl:
      return {d->ctrl};
    case StateField::kQaccWarmstart:
      return {d->qacc_warmstart};
    case StateField::kQfrcApplied:
      return {d->qfrc_applied};
    case StateField::kXfrcApplied:
      return {d->xfrc_applied};
    case StateField::kMocapPos:
      return {d->mocap_pos};
    case StateField::kMocapQuat:
      return {d->mocap_quat};
    case StateField::kUserdata:
      return {d->userdata};
    case StateField::kControllerNextUpdate:
      return {};
    case StateField::kHistory:
      return {d->history};
    case StateField::kEqActive:
      return {nullptr, d->eq_active};
    case StateField::kPluginState:
      return {d->plugin_state};
    case StateField::kPlastic:
      return {d->plastic};
  }
  return {};
}

void ReadMujocoState(const mjData* d, StateField field, std::span<double> out) {
  // reading only: the array is not written through
  const MujocoStateArray a = MujocoStateArrayOf(const_cast<mjData*>(d), field);
  if (out.empty()) return;
  if (a.num) std::copy(a.num, a.num + out.size(), out.begin());
  if (a.flag)
    for (size_t i = 0; i < out.size(); ++i) out[i] = a.flag[i] ? 1.0 : 0.0;
}

void WriteMujocoState(mjData* d, StateField field, std::span<const double> in) {
  const MujocoStateArray a = MujocoStateArrayOf(d, field);
  if (in.empty()) return;
  if (a.num) std::memcpy(a.num, in.data(), sizeof(mjtNum) * in.size());
  if (a.flag)
    for (size_t i = 0; i < in.size(); ++i) a.flag[i] = in[i] != 0;
}

void CopyMujocoState(const mjData* src, mjData* dst, StateField field, int64_t n) {
  const MujocoStateArray from = MujocoStateArrayOf(const_cast<mjData*>(src), field);
  const MujocoStateArray to = MujocoStateArrayOf(dst, field);
  if (n <= 0) return;
  if (from.num) std::memcpy(to.num, from.num, sizeof(mjtNum) * n);
  if (from.flag) std::memcpy(to.flag, from.flag, sizeof(mjtBool) * n);
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
      case StateDim::kNhistory:
        dims[dim] = m->nhistory;
        break;
      case StateDim::kNeq:
        dims[dim] = m->neq;
        break;
      case StateDim::kNpluginstate:
        dims[dim] = m->npluginstate;
        break;
      case StateDim::kNplastic:
        dims[dim] = m->nplastic;
        break;
    }
  }
  return dims;
}

}  // namespace penumbra
