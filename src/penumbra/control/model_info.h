#pragma once
// names, sizes and index maps of a compiled model, as controllers see it: enough
// to resolve the joints, actuators, bodies, sensors and sites a controller needs
// and to find their entries in qpos / qvel / ctrl / sensordata, without mujoco.h.
// filled by physics/simulation from the mjModel (MuJoCo ids are the indices here).

#include <string>
#include <vector>

namespace penumbra {

/// kind of named model object a controller can ask for.
enum class ModelObject { kBody, kJoint, kActuator, kSensor, kSite };

/// lowercase English name of a kind ("body", "joint", ...), for messages.
const char* ModelObjectName(ModelObject kind);

/// a joint of the model (MuJoCo jnt_* arrays).
struct JointInfo {
  enum class Type { kFree, kBall, kSlide, kHinge };
  std::string name;
  Type type = Type::kHinge;
  int qpos_adr = 0;  ///< first index in qpos (free: 7 entries, ball: 4, slide/hinge: 1)
  int dof_adr = 0;   ///< first index in qvel (free: 6, ball: 3, slide/hinge: 1)
  int body = 0;      ///< body the joint moves
  bool limited = false;
  double range[2] = {0, 0};  ///< limits (m or rad) when limited
};

/// an actuator (MuJoCo actuator_* arrays); its control is ctrl[index].
struct ActuatorInfo {
  std::string name;
  int joint = -1;  ///< joint it drives (joint transmission), else -1
  bool ctrl_limited = false;
  double ctrl_range[2] = {0, 0};  ///< clamp range of ctrl when ctrl_limited
};

/// a sensor (MuJoCo sensor_* arrays); its values are sensordata[adr .. adr + dim).
struct SensorInfo {
  std::string name;
  int adr = 0;
  int dim = 0;
};

/// the model as controllers see it. indices are MuJoCo ids; index 0 of bodies is the world.
struct ModelInfo {
  int nq = 0;           ///< size of qpos
  int nv = 0;           ///< size of qvel (degrees of freedom)
  int nu = 0;           ///< size of ctrl
  int nsensordata = 0;  ///< size of sensordata
  double timestep_sec = 0.002;
  std::vector<std::string> body_names;  ///< (nbody)
  std::vector<int> body_parent;         ///< (nbody) parent body index, -1 for the world
  std::vector<std::string> site_names;  ///< (nsite)
  std::vector<int> site_body;           ///< (nsite) body each site is fixed to
  std::vector<JointInfo> joints;        ///< (njnt)
  std::vector<ActuatorInfo> actuators;  ///< (nu)
  std::vector<SensorInfo> sensors;      ///< (nsensor)

  /// index of the object of `kind` named `name` (exact match), or -1.
  int Find(ModelObject kind, const std::string& name) const;
  /// every name of `kind`, in id order (unnamed objects give "").
  std::vector<std::string> Names(ModelObject kind) const;
};

}  // namespace penumbra
