#include "penumbra/control/actuator_drive.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace penumbra {

double CtrlForEffort(const ActuatorInfo& a, double tau, double q, double qd) {
  const double gear = a.gear[0];
  double f = tau / gear;
  if (a.force_limited) f = std::clamp(f, a.force_range[0], a.force_range[1]);
  double u = 0;
  switch (a.drive) {
    case ActuatorDrive::kPositionServo:
      u = gear * q + (f + a.kv * gear * qd) / a.kp;
      break;
    case ActuatorDrive::kVelocityServo:
      u = gear * qd + f / a.kv;
      break;
    case ActuatorDrive::kMotor:
    case ActuatorDrive::kOther:
      u = f / a.gain;
      break;
  }
  if (a.ctrl_limited) u = std::clamp(u, a.ctrl_range[0], a.ctrl_range[1]);
  return u;
}

double MaxEffort(const ActuatorInfo& a) {
  const double gear = std::abs(a.gear[0]);
  double f = std::numeric_limits<double>::infinity();
  if (a.force_limited) f = std::max(std::abs(a.force_range[0]), std::abs(a.force_range[1]));
  if (a.drive == ActuatorDrive::kMotor && a.ctrl_limited) {
    f = std::min(f,
                 std::max(std::abs(a.ctrl_range[0]), std::abs(a.ctrl_range[1])) * std::abs(a.gain));
  }
  return f * gear;
}

std::optional<std::string> EffortDriveProblem(const ActuatorInfo& a) {
  const std::string name = "actuator '" + a.name + "'";
  if (a.joint < 0) return name + " has no joint transmission; expected an actuator on a joint";
  if (a.gear[0] == 0) return name + " has gear 0";
  switch (a.drive) {
    case ActuatorDrive::kMotor:
      if (a.gain == 0) return name + " is a motor with gain 0";
      return std::nullopt;
    case ActuatorDrive::kPositionServo:
      if (!(a.kp > 0)) return name + " is a position servo with kp <= 0";
      return std::nullopt;
    case ActuatorDrive::kVelocityServo:
      if (!(a.kv > 0)) return name + " is a velocity servo with kv <= 0";
      return std::nullopt;
    case ActuatorDrive::kOther:
      break;
  }
  return name + " is a general actuator (" + a.drive_detail +
         ") whose force the controller cannot set; expected a motor, position servo "
         "(<position>) or velocity servo (<velocity>) without activation dynamics";
}

}  // namespace penumbra
