#include "penumbra/physics/sensor_snapshot.h"

#include "penumbra/physics/mujoco_state.h"

namespace penumbra {

void CopyStateForForward(const mjModel* m, const mjData* live, mjData* d) {
  d->time = live->time;
  const StateDims dims = MujocoStateDims(m, 0);
  for (const StateFieldInfo& f : kStateFields)
    if (f.mujoco) CopyMujocoState(live, d, f.field, StateFieldSize(f, dims));
}

void FillSensorGroundTruth(const mjModel* m, const mjData* d, WorldSnapshot* out) {
  out->sensordata.assign(d->sensordata, d->sensordata + m->nsensordata);
  out->V_WB.resize(m->nbody);
  for (int b = 0; b < m->nbody; ++b) {
    mjtNum v[6];
    mj_objectVelocity(m, d, mjOBJ_XBODY, b, v, 0);
    for (int k = 0; k < 6; ++k) out->V_WB[b][k] = v[k];
  }
  out->qfrc_actuator.assign(d->qfrc_actuator, d->qfrc_actuator + m->nv);
  out->contacts.resize(d->ncon);
  for (int i = 0; i < d->ncon; ++i) {
    const mjContact& c = d->contact[i];
    WorldSnapshot::Contact& o = out->contacts[i];
    o.geom1 = c.geom1;
    o.geom2 = c.geom2;
    o.body1 = c.geom1 >= 0 ? m->geom_bodyid[c.geom1] : -1;
    o.body2 = c.geom2 >= 0 ? m->geom_bodyid[c.geom2] : -1;
    o.p_W = Eigen::Vector3d(c.pos[0], c.pos[1], c.pos[2]);
    o.normal_W = Eigen::Vector3d(c.frame[0], c.frame[1], c.frame[2]);
    o.distance_m = c.dist;
    mjtNum f[6];
    mj_contactForce(m, d, i, f);
    o.force_N = Eigen::Vector3d(f[0], f[1], f[2]);
  }
}

}  // namespace penumbra
