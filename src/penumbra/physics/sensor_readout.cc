#include "penumbra/physics/sensor_readout.h"

#include <mujoco/mujoco.h>

#include <cstdint>
#include <string>

#include "penumbra/core/error.h"

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
    case mjSENS_CAMPROJECTION:
      return "camprojection";
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
    case mjSENS_JOINTACTFRC:
      return "jointactuatorfrc";
    case mjSENS_TENDONACTFRC:
      return "tendonactuatorfrc";
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
    case mjSENS_INSIDESITE:
      return "insidesite";
    case mjSENS_GEOMDIST:
      return "distance";
    case mjSENS_GEOMNORMAL:
      return "normal";
    case mjSENS_GEOMFROMTO:
      return "fromto";
    case mjSENS_CONTACT:
      return "contact";
    case mjSENS_E_POTENTIAL:
      return "e_potential";
    case mjSENS_E_KINETIC:
      return "e_kinetic";
    case mjSENS_CLOCK:
      return "clock";
    case mjSENS_TACTILE:
      return "tactile";
    case mjSENS_PLUGIN:
      return "plugin";
    case mjSENS_USER:
      return "user";
    default:
      return nullptr;
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
    case mjSENS_TENDONACTFRC:
      return "N";
    case mjSENS_TORQUE:
      return "N m";
    case mjSENS_CAMPROJECTION:
      return "px";
    case mjSENS_GEOMDIST:
    case mjSENS_GEOMFROMTO:
      return "m";
    case mjSENS_INSIDESITE:
    case mjSENS_GEOMNORMAL:
      return "1";
    case mjSENS_E_POTENTIAL:
    case mjSENS_E_KINETIC:
      return "J";
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
      // distances only (the default data); other fields carry their units in the labels
      return m->sensor_intprm[mjNSENS * s] <= 1 ? "m" : "";
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
    case mjSENS_JOINTACTFRC:
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
      // contact, tactile and multi-field rangefinders: per value (Components); user and
      // plugin sensors: whatever the callback or plugin writes
      return "";
  }
}

// one named field of a multi-field sensor: its name, number of values and unit as a label
// suffix ("m_s" for m/s, "" for dimensionless)
struct Field {
  const char* name;
  int size;
  const char* unit;
};

// the contact sensor's fields in mjtConDataField order (MuJoCo XML reference, sensor/contact
// "data"): found is the number of matching contacts (0 = empty slot)
constexpr Field kContactFields[mjNCONDATA] = {
    {"found", 1, ""},   {"force", 3, "N"},    {"torque", 3, "N_m"},
    {"dist", 1, "m"},   {"pos", 3, "m"},      {"normal", 3, ""},
    {"tangent", 3, ""}, {"linvel", 3, "m_s"}, {"angvel", 3, "rad_s"}};
// the rangefinder's fields in mjtRayDataField order (sensor/rangefinder "data")
constexpr Field kRayFields[mjNRAYDATA] = {{"dist", 1, "m"},  {"dir", 3, ""},    {"origin", 3, "m"},
                                          {"point", 3, "m"}, {"normal", 3, ""}, {"depth", 1, "m"}};

// labels "<prefix><field>[_x|_y|_z][_<unit>]" of the fields set in bit mask `spec`
void AppendFields(const Field* fields, int nfields, int spec, const std::string& prefix,
                  std::vector<std::string>* out) {
  static const char* kAxes[3] = {"x", "y", "z"};
  for (int f = 0; f < nfields; ++f) {
    if (!(spec & (1 << f))) continue;
    const std::string unit = fields[f].unit;
    for (int k = 0; k < fields[f].size; ++k) {
      std::string label = prefix + fields[f].name;
      if (fields[f].size == 3) label += std::string("_") + kAxes[k];
      if (!unit.empty()) label += "_" + unit;
      out->push_back(std::move(label));
    }
  }
}

int FieldsSize(const Field* fields, int nfields, int spec) {
  int n = 0;
  for (int f = 0; f < nfields; ++f)
    if (spec & (1 << f)) n += fields[f].size;
  return n;
}

std::string Quoted(const std::string& name, int s) {
  return name.empty() ? "#" + std::to_string(s) : "'" + name + "'";
}

// the per-value labels of sensor s (SensorDescription::components); empty when the sensor's
// layout does not match what MuJoCo documents for its attributes.
std::vector<std::string> Components(const mjModel* m, int s) {
  const int t = m->sensor_type[s];
  const int dim = m->sensor_dim[s];
  const int* prm = m->sensor_intprm + mjNSENS * s;
  std::vector<std::string> c;
  if (t == mjSENS_CONTACT) {
    // num slots of the fields in data (intprm: data bit mask, reduce, num)
    const int spec = prm[0], num = prm[2];
    const int per = FieldsSize(kContactFields, mjNCONDATA, spec);
    if (per <= 0 || num <= 0 || static_cast<int64_t>(per) * num != dim) return {};
    for (int slot = 0; slot < num; ++slot)
      AppendFields(kContactFields, mjNCONDATA, spec, std::to_string(slot) + "_", &c);
    return c;
  }
  if (t == mjSENS_RANGEFINDER) {
    // one ray (site) or one per camera pixel, each with the fields in data (intprm[0]); a
    // site's plain distance keeps the scalar label
    const int spec = prm[0] == 0 ? 1 : prm[0];
    const int per = FieldsSize(kRayFields, mjNRAYDATA, spec);
    if (per <= 0 || dim % per != 0) return {};
    const int rays = dim / per;
    if (spec == 1) {
      if (rays == 1) return {""};
      for (int r = 0; r < rays; ++r) c.push_back(std::to_string(r));
      return c;
    }
    for (int r = 0; r < rays; ++r)
      AppendFields(kRayFields, mjNRAYDATA, spec, rays == 1 ? "" : std::to_string(r) + "_", &c);
    return c;
  }
  if (t == mjSENS_TACTILE) {
    // three blocks of one value per taxel (mesh vertex): penetration depth, then the two
    // tangential sliding speeds
    if (dim % 3 != 0) return {};
    const int n = dim / 3;
    for (const char* block : {"depth_", "slip1_", "slip2_"})
      for (int i = 0; i < n; ++i)
        c.push_back(block + std::to_string(i) + (std::string(block) == "depth_" ? "_m" : "_m_s"));
    return c;
  }
  if (t == mjSENS_CAMPROJECTION) return dim == 2 ? std::vector<std::string>{"u", "v"} : c;
  if (t == mjSENS_GEOMFROMTO) {
    if (dim != 6) return {};
    return {"from_x", "from_y", "from_z", "to_x", "to_y", "to_z"};
  }
  if (dim == 4 && (t == mjSENS_BALLQUAT || t == mjSENS_FRAMEQUAT)) return {"w", "x", "y", "z"};
  if (dim == 3) return {"x", "y", "z"};
  if (dim == 1) return {""};
  for (int k = 0; k < dim; ++k) c.push_back(std::to_string(k));
  return c;
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
    const char* type = TypeName(m->sensor_type[s]);
    if (type == nullptr)
      throw Error("MuJoCo sensor " + Quoted(i.name, s) + " has sensor type " +
                  std::to_string(m->sensor_type[s]) +
                  ", which Penumbra does not know (physics/sensor_readout.h lists the types it "
                  "reads)");
    i.id = s;
    i.type = type;
    i.adr = m->sensor_adr[s];
    i.dim = m->sensor_dim[s];
    i.unit = Unit(m, s);
    i.components = Components(m, s);
    if (static_cast<int>(i.components.size()) != i.dim)
      throw Error("MuJoCo sensor " + Quoted(i.name, s) + " (" + type + ") has " +
                  std::to_string(i.dim) +
                  " values, which do not match the layout its attributes give (MuJoCo XML "
                  "reference, sensor/" +
                  type + ")");
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
