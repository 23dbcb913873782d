#include "penumbra/physics/sensor_snapshot.h"

#include <cstring>

namespace penumbra {

void CopyStateForForward(const mjModel* m, const mjData* live, mjData* d) {
  d->time = live->time;
  std::memcpy(d->qpos, live->qpos, sizeof(mjtNum) * m->nq);
  std::memcpy(d->qvel, live->qvel, sizeof(mjtNum) * m->nv);
  std::memcpy(d->act, live->act, sizeof(mjtNum) * m->na);
  std::memcpy(d->ctrl, live->ctrl, sizeof(mjtNum) * m->nu);
  std::memcpy(d->qfrc_applied, live->qfrc_applied, sizeof(mjtNum) * m->nv);
  std::memcpy(d->xfrc_applied, live->xfrc_applied, sizeof(mjtNum) * 6 * m->nbody);
  std::memcpy(d->mocap_pos, live->mocap_pos, sizeof(mjtNum) * 3 * m->nmocap);
  std::memcpy(d->mocap_quat, live->mocap_quat, sizeof(mjtNum) * 4 * m->nmocap);
  std::memcpy(d->qacc_warmstart, live->qacc_warmstart, sizeof(mjtNum) * m->nv);
  std::memcpy(d->userdata, live->userdata, sizeof(mjtNum) * m->nuserdata);
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
