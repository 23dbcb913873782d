#pragma once
// names, sizes and index maps of a compiled model, as controllers see it: enough
// to resolve the joints, actuators, bodies, sensors and sites a controller needs
// and to find their entries in qpos / qvel / ctrl / sensordata, without mujoco.h.
// filled by physics/simulation from the mjModel (MuJoCo ids are the indices here).

#include <string>
#include <vector>

#include "penumbra/core/pose.h"

namespace penumbra {

/// kind of named model object a controller can ask for.
enum class ModelObject { kBody, kJoint, kActuator, kSensor, kSite, kKey };

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
  /// hinge / slide: the axis (unit) and the anchor point in the frame of `body` (MuJoCo
  /// jnt_axis, jnt_pos), and the joint's value in the model's rest configuration (qpos0,
  /// = the MJCF ref; rad or m): body_X_PB are the frames at these values.
  Eigen::Vector3d axis_B = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d pos_B = Eigen::Vector3d::Zero();
  double qpos0 = 0;
};

/// how an actuator turns its ctrl u into its scalar force f (MuJoCo's gain/bias model,
/// f = gain u + b0 + b1 L + b2 Ldot with L the actuator length = gear q for a joint
/// transmission; XML reference "actuator"): which of MJCF's shortcut actuators it is.
enum class ActuatorDrive {
  kMotor,          ///< <motor> / fixed gain, no bias, no dynamics: f = gain u
  kPositionServo,  ///< <position>: f = kp (u - L) - kv Ldot (kv from a <general> bias)
  kVelocityServo,  ///< <velocity>: f = kv (u - Ldot)
  kOther,          ///< activation dynamics, muscle/user gain or bias, any other bias
};

/// lowercase description of a drive ("motor", "position servo", ...), for messages.
const char* ActuatorDriveName(ActuatorDrive drive);

/// an actuator (MuJoCo actuator_* arrays); its control is ctrl[index].
struct ActuatorInfo {
  std::string name;
  int joint = -1;  ///< joint it drives (joint transmission), else -1
  bool ctrl_limited = false;
  double ctrl_range[2] = {0, 0};  ///< clamp range of ctrl when ctrl_limited
  int site = -1;  ///< site it acts on (site transmission, e.g. a rotor's thrust), else -1
  /// actuator_gear: for a site transmission, the (force xyz, torque xyz) the actuator applies
  /// per unit of its scalar force, in the site frame; for a joint transmission gear[0] is the
  /// joint gear ratio.
  double gear[6] = {1, 0, 0, 0, 0, 0};
  ActuatorDrive drive = ActuatorDrive::kMotor;
  double gain = 1;        ///< motor: force per unit ctrl (gainprm[0])
  double kp = 0, kv = 0;  ///< servo gains (N/m or N m/rad; N s/m or N m s/rad per unit length)
  /// MuJoCo's words for what makes the drive kOther, e.g. "dyntype filter", for messages.
  std::string drive_detail;
  bool force_limited = false;
  double force_range[2] = {0, 0};  ///< clamp range of the force when force_limited
};

/// a sensor (MuJoCo sensor_* arrays); its values are sensordata[adr .. adr + dim).
struct SensorInfo {
  std::string name;
  int adr = 0;
  int dim = 0;
};

/// a keyframe (MuJoCo <key>, key_* arrays).
struct KeyInfo {
  std::string name;
  double time_sec = 0;       ///< key_time
  std::vector<double> qpos;  ///< (nq) key_qpos
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
  /// (nbody) mass properties and rest frames (MuJoCo body_mass, body_inertia, body_pos /
  /// body_quat, body_ipos / body_iquat); empty when the model info was built by hand.
  std::vector<double> body_mass;              ///< kg
  std::vector<Eigen::Vector3d> body_inertia;  ///< principal moments about the COM (kg m^2)
  std::vector<Pose> body_X_PB;  ///< X_PB: body in its parent's frame at qpos0 (world: identity)
  std::vector<Pose> body_X_BI;  ///< X_BI: inertial frame (origin at the COM, principal axes)
  std::vector<std::string> site_names;  ///< (nsite)
  std::vector<int> site_body;           ///< (nsite) body each site is fixed to
  std::vector<Pose> site_X_BS;          ///< (nsite) X_BS: site in its body's frame (site_pos/quat)
  std::vector<JointInfo> joints;        ///< (njnt)
  std::vector<ActuatorInfo> actuators;  ///< (nu)
  std::vector<SensorInfo> sensors;      ///< (nsensor)
  std::vector<KeyInfo> keys;            ///< (nkey) keyframes; empty when built by hand

  /// index of the object of `kind` named `name` (exact match), or -1.
  int Find(ModelObject kind, const std::string& name) const;
  /// every name of `kind`, in id order (unnamed objects give "").
  std::vector<std::string> Names(ModelObject kind) const;
};

}  // namespace penumbra
