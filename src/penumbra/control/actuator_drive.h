#pragma once
// joint efforts through whatever actuator a model has on the joint: a torque controller
// (trot_gait, joint servos in torque output) computes the effort tau (N m or N) a joint
// should get and this turns it into the ctrl of the joint's actuator, by the actuator's
// own force law (control/model_info.h ActuatorDrive; MuJoCo XML reference "actuator"):
//   motor:          f = gain u                       -> u = f / gain
//   position servo: f = kp (u - L) - kv Ldot          -> u = L + (f + kv Ldot) / kp
//   velocity servo: f = kv (u - Ldot)                 -> u = Ldot + f / kv
// with f = tau / gear the actuator force, L = gear q and Ldot = gear qdot (joint
// transmission). the servo forms hold exactly at the state they were computed from; between
// controller updates the servo's own stiffness acts around it. the force is first clamped
// to the actuator's forcerange (when force-limited), the ctrl then to its ctrlrange.

#include <optional>
#include <string>

#include "penumbra/control/model_info.h"

namespace penumbra {

/// the ctrl that makes `actuator` (joint transmission, gear[0] != 0, drive not kOther)
/// apply the joint effort `tau` (N m or N) at joint position `q` (rad or m) and velocity
/// `qd` (rad/s or m/s), clamped as the file comment says.
double CtrlForEffort(const ActuatorInfo& actuator, double tau, double q, double qd);

/// the largest joint effort |tau| (N m or N) the actuator can apply by its forcerange, or
/// by its ctrlrange for a motor (|ctrl| x gain x |gear|); infinity when unlimited.
double MaxEffort(const ActuatorInfo& actuator);

/// nullopt when CtrlForEffort can drive `actuator`; else why not, naming the actuator and
/// its type, e.g. "actuator 'go1/FR_hip' is a general actuator (dyntype filter): ...".
std::optional<std::string> EffortDriveProblem(const ActuatorInfo& actuator);

}  // namespace penumbra
