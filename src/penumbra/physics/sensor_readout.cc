#include "penumbra/physics/sensor_readout.h"

#include <mujoco/mujoco.h>

namespace penumbra {
namespace {

const char* TypeName(int t) {
  switch (t) {
    case mjSENS_TOUCH:
      return "touch";
    case mjSENS_ACCELEROMETER:
      return "accelerometer";
    case mjSENS_VELOCIMETER:
      return "velocimeter";
    case mjSENS_GYRO:
      return "gyro";
    case mjSENS_FORCE:
      return "force";
    case mjSENS_TORQUE:
      return "torque";
    case mjSENS_MAGNETOMETER:
      return "magnetometer";
    case mjSENS_RANGEFINDER:
      return "rangefinder";
    case mjSENS_JOINTPOS:
      return "jointpos";
    case mjSENS_JOINTVEL:
      return "jointvel";
    case mjSENS_TENDONPOS:
      return "tendonpos";
    case mjSENS_TENDONVEL:
      return "tendonvel";
    case mjSENS_ACTUATORPOS:
      return "actuatorpos";
    case mjSENS_ACTUATORVEL:
      return "actuatorvel";
    case mjSENS_ACTUATORFRC:
      return "actuatorfrc";
    case mjSENS_BALLQUAT:
      return "ballquat";
    case mjSENS_BALLANGVEL:
      return "ballangvel";
    case mjSENS_JOINTLIMITPOS:
      return "jointlimitpos";
    case mjSENS_JOINTLIMITVEL:
      return "jointlimitvel";
    case mjSENS_JOINTLIMITFRC:
      return "jointlimitfrc";
    case mjSENS_TENDONLIMITPOS:
      return "tendonlimitpos";
    case mjSENS_TENDONLIMITVEL:
      return "tendonlimitvel";
    case mjSENS_TENDONLIMITFRC:
      return "tendonlimitfrc";
    case mjSENS_FRAMEPOS:
      return "framepos";
    case mjSENS_FRAMEQUAT:
      return "framequat";
    case mjSENS_FRAMEXAXIS:
      return "framexaxis";
    case mjSENS_FRAMEYAXIS:
      return "frameyaxis";
    case mjSENS_FRAMEZAXIS:
      return "framezaxis";
    case mjSENS_FRAMELINVEL:
      return "framelinvel";
    case mjSENS_FRAMEANGVEL:
      return "frameangvel";
    case mjSENS_FRAMELINACC:
      return "framelinacc";
    case mjSENS_FRAMEANGACC:
      return "frameangacc";
    case mjSENS_SUBTREECOM:
      return "subtreecom";
    case mjSENS_SUBTREELINVEL:
      return "subtreelinvel";
    case mjSENS_SUBTREEANGMOM:
      return "subtreeangmom";
    case mjSENS_CLOCK:
      return "clock";
    default:
      return "user";
  }
}

const char* ObjName(int t) {
  switch (t) {
    case mjOBJ_BODY:
      return "body";
    case mjOBJ_XBODY:
      return "xbody";
    case mjOBJ_JOINT:
      return "joint";
    case mjOBJ_GEOM:
      return "geom";
    case mjOBJ_SITE:
      return "site";
    case mjOBJ_CAMERA:
      return "camera";
    case mjOBJ_TENDON:
      return "tendon";
    case mjOBJ_ACTUATOR:
      return "actuator";
    default:
      return "";
  }
}

// joint-like unit: rad for hinge (and ball), m for slide
std::string JointUnit(const mjModel* m, int joint, const char* rad, const char* lin) {
  if (joint < 0 || joint >= m->njnt) return rad;
  return m->jnt_type[joint] == mjJNT_SLIDE ? lin : rad;
}

std::string ActuatorUnit(const mjModel* m, int act, bool force, bool vel) {
  if (act < 0 || act >= m->nu) return "";
  const int trn = m->actuator_trntype[act];
  if (trn == mjTRN_JOINT || trn == mjTRN_JOINTINPARENT) {
    const bool slide = m->jnt_type[m->actuator_trnid[2 * act]] == mjJNT_SLIDE;
    if (force) return slide ? "N" : "N m";
    if (vel) return slide ? "m/s" : "rad/s";
    return slide ? "m" : "rad";
  }
  if (trn == mjTRN_TENDON) return force ? "N" : (vel ? "m/s" : "m");
  // site / slider-crank transmissions: generalised units of the gear
  return force ? "N or N m" : (vel ? "m/s or rad/s" : "m or rad");
}

std::string Unit(const mjModel* m, int s) {
  const int obj = m->sensor_objid[s];
  switch (m->sensor_type[s]) {
    case mjSENS_TOUCH:
    case mjSENS_FORCE:
    case mjSENS_TENDONLIMITFRC:
      return "N";
    case mjSENS_TORQUE:
      return "N m";
    case mjSENS_ACCELEROMETER:
    case mjSENS_FRAMELINACC:
      return "m/s^2";
    case mjSENS_VELOCIMETER:
    case mjSENS_FRAMELINVEL:
    case mjSENS_SUBTREELINVEL:
    case mjSENS_TENDONVEL:
    case mjSENS_TENDONLIMITVEL:
      return "m/s";
    case mjSENS_GYRO:
    case mjSENS_FRAMEANGVEL:
    case mjSENS_BALLANGVEL:
      return "rad/s";
    case mjSENS_FRAMEANGACC:
      return "rad/s^2";
    case mjSENS_MAGNETOMETER:
      return "option.magnetic units (T)";
    case mjSENS_RANGEFINDER:
    case mjSENS_FRAMEPOS:
    case mjSENS_SUBTREECOM:
    case mjSENS_TENDONPOS:
    case mjSENS_TENDONLIMITPOS:
      return "m";
    case mjSENS_JOINTPOS:
    case mjSENS_JOINTLIMITPOS:
      return JointUnit(m, obj, "rad", "m");
    case mjSENS_JOINTVEL:
    case mjSENS_JOINTLIMITVEL:
      return JointUnit(m, obj, "rad/s", "m/s");
    case mjSENS_JOINTLIMITFRC:
      return JointUnit(m, obj, "N m", "N");
    case mjSENS_ACTUATORPOS:
      return ActuatorUnit(m, obj, false, false);
    case mjSENS_ACTUATORVEL:
      return ActuatorUnit(m, obj, false, true);
    case mjSENS_ACTUATORFRC:
      return ActuatorUnit(m, obj, true, false);
    case mjSENS_BALLQUAT:
    case mjSENS_FRAMEQUAT:
    case mjSENS_FRAMEXAXIS:
    case mjSENS_FRAMEYAXIS:
    case mjSENS_FRAMEZAXIS:
      return "1";
    case mjSENS_SUBTREEANGMOM:
      return "kg m^2/s";
    case mjSENS_CLOCK:
      return "s";
    default:
      return "user";
  }
}

std::string SensorObjectName(const mjModel* m, int type, int id) {
  if (id < 0) return "";
  const char* n = mj_id2name(m, type, id);
  return n ? n : "";
}

}  // namespace

std::vector<SensorDescription> DescribeMujocoSensors(const mjModel_* mm) {
  const mjModel* m = mm;
  std::vector<SensorDescription> out;
  for (int s = 0; s < m->nsensor; ++s) {
    SensorDescription i;
    i.name = SensorObjectName(m, mjOBJ_SENSOR, s);
    i.id = s;
    i.type = TypeName(m->sensor_type[s]);
    i.adr = m->sensor_adr[s];
    i.dim = m->sensor_dim[s];
    i.unit = Unit(m, s);
    const int t = m->sensor_type[s];
    if (i.dim == 4 && (t == mjSENS_BALLQUAT || t == mjSENS_FRAMEQUAT)) {
      i.components = {"w", "x", "y", "z"};
    } else if (i.dim == 3) {
      i.components = {"x", "y", "z"};
    } else if (i.dim == 1) {
      i.components = {""};
    } else {
      for (int k = 0; k < i.dim; ++k) i.components.push_back(std::to_string(k));
    }
    i.object_type = ObjName(m->sensor_objtype[s]);
    i.object_name = SensorObjectName(m, m->sensor_objtype[s], m->sensor_objid[s]);
    if (m->sensor_reftype[s] > 0 && m->sensor_refid[s] >= 0)
      i.reference_name = SensorObjectName(m, m->sensor_reftype[s], m->sensor_refid[s]);
    i.noise_stddev = m->sensor_noise[s];
    i.cutoff = m->sensor_cutoff[s];
    out.push_back(std::move(i));
  }
  return out;
}

}  // namespace penumbra
