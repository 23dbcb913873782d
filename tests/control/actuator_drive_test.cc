// a joint effort becomes the ctrl that the actuator's own force law turns
// back into that effort (motors, position servos, velocity servos), within forcerange and
// ctrlrange; actuators of other kinds are named with their type.
#include "penumbra/control/actuator_drive.h"

#include <gtest/gtest.h>

#include <cmath>

namespace penumbra {
namespace {

// MuJoCo's force for ctrl u at joint state (q, qd), as joint effort (gear f)
double Effort(const ActuatorInfo& a, double u, double q, double qd) {
  const double g = a.gear[0], L = g * q, Ld = g * qd;
  double f = 0;
  switch (a.drive) {
    case ActuatorDrive::kMotor:
      f = a.gain * u;
      break;
    case ActuatorDrive::kPositionServo:
      f = a.kp * (u - L) - a.kv * Ld;
      break;
    case ActuatorDrive::kVelocityServo:
      f = a.kv * (u - Ld);
      break;
    case ActuatorDrive::kOther:
      break;
  }
  if (a.force_limited) f = std::clamp(f, a.force_range[0], a.force_range[1]);
  return g * f;
}

ActuatorInfo Actuator(ActuatorDrive drive, double gear) {
  ActuatorInfo a;
  a.name = "leg/knee";
  a.joint = 0;
  a.drive = drive;
  a.gear[0] = gear;
  a.gain = drive == ActuatorDrive::kMotor ? 2.0 : 1.0;
  a.kp = 100;
  a.kv = drive == ActuatorDrive::kVelocityServo ? 8 : 3;
  return a;
}

TEST(ActuatorDrive, CtrlReproducesTheEffortThroughEachForceLaw) {
  for (ActuatorDrive d :
       {ActuatorDrive::kMotor, ActuatorDrive::kPositionServo, ActuatorDrive::kVelocityServo}) {
    for (double gear : {1.0, -2.5}) {
      const ActuatorInfo a = Actuator(d, gear);
      EXPECT_FALSE(EffortDriveProblem(a).has_value()) << ActuatorDriveName(d);
      for (double tau : {-7.0, 0.0, 12.5}) {
        const double q = 0.4, qd = -1.3;
        const double u = CtrlForEffort(a, tau, q, qd);
        EXPECT_NEAR(Effort(a, u, q, qd), tau, 1e-12) << ActuatorDriveName(d) << " gear " << gear;
      }
    }
  }
}

TEST(ActuatorDrive, ForceThenCtrlRangesClamp) {
  ActuatorInfo a = Actuator(ActuatorDrive::kPositionServo, 1);
  a.force_limited = true;
  a.force_range[0] = -5;
  a.force_range[1] = 5;
  EXPECT_NEAR(Effort(a, CtrlForEffort(a, 50, 0.2, 0), 0.2, 0), 5, 1e-12);
  a.ctrl_limited = true;
  a.ctrl_range[0] = -0.5;
  a.ctrl_range[1] = 0.21;
  EXPECT_EQ(CtrlForEffort(a, 50, 0.2, 0), 0.21);
  EXPECT_EQ(MaxEffort(a), 5);
}

TEST(ActuatorDrive, OtherActuatorsAreNamedWithTheirType) {
  ActuatorInfo a = Actuator(ActuatorDrive::kOther, 1);
  a.drive_detail = "dyntype 2: activation dynamics (integrator/filter/muscle/user)";
  const auto problem = EffortDriveProblem(a);
  ASSERT_TRUE(problem.has_value());
  EXPECT_NE(problem->find("actuator 'leg/knee' is a general actuator (dyntype 2"),
            std::string::npos)
      << *problem;
  a.drive = ActuatorDrive::kPositionServo;
  a.kp = 0;
  EXPECT_NE(EffortDriveProblem(a)->find("position servo with kp <= 0"), std::string::npos);
}

}  // namespace
}  // namespace penumbra
