#pragma once
// kinematics of a three-joint quadruped leg (abduction - hip pitch - knee), the leg of the
// Unitree Go1/A1/B1, MIT Mini Cheetah, ANYmal-like robots in their canonical convention:
//
//   hip frame H: origin on the hip (abduction) axis, axes parallel to the base frame
//     (REP-103: x forward, y left, z up) when the abduction angle is zero.
//   q = (q_hip, q_thigh, q_calf) (rad): q_hip rotates about +x of H; q_thigh and q_calf
//     rotate about the leg's +y axis; all zero = leg straight down; q_thigh > 0 swings the
//     foot backwards; q_calf < 0 folds the knee (knee behind the foot line).
//   geometry: the thigh (pitch) axis sits `abduction_m` along y of the abducted hip frame
//     (signed: > 0 for left legs, < 0 for right legs); thigh length l2 = `thigh_m` from the
//     pitch axis to the knee axis, calf length l3 = `calf_m` from the knee axis to the foot
//     point (e.g. the centre of a spherical foot).
//
// forward kinematics (foot position p in H):
//   x  = -l2 sin(q2) - l3 sin(q2 + q3)
//   z' = -l2 cos(q2) - l3 cos(q2 + q3)          (leg plane, before abduction)
//   p  = Rx(q1) (x, l1, z')
// inverse kinematics in closed form: the abduction angle from the circle the foot lies on in
// the y-z plane, then the planar two-link solution by the law of cosines (J. J. Craig,
// "Introduction to Robotics: Mechanics and Control", 3rd ed., 2005, sec. 4.4):
//   z' = -sqrt(py^2 + pz^2 - l1^2)               (foot below the hip)
//   q1 = atan2(pz, py) - atan2(z', l1)
//   q3 = -acos((x^2 + z'^2 - l2^2 - l3^2) / (2 l2 l3))   (knee backwards)
//   q2 = atan2(-x, -z') - atan2(l3 sin q3, l2 + l3 cos q3)
// targets outside the workspace are moved onto its boundary (the leg then points at the
// target as far as it reaches), so IK always returns finite angles.

#include <Eigen/Core>

namespace penumbra {

/// lengths of one leg (m); see the file comment for the convention.
struct LegGeometry {
  double abduction_m = 0.08;  ///< l1, signed: > 0 for a left leg, < 0 for a right leg
  double thigh_m = 0.213;     ///< l2 > 0
  double calf_m = 0.213;      ///< l3 > 0
};

/// foot position in the hip frame H for joint angles `q` (canonical convention).
Eigen::Vector3d LegForwardKinematics(const LegGeometry& leg, const Eigen::Vector3d& q);

/// d(foot position in H) / dq (3 x 3), the leg's analytic Jacobian at `q`.
Eigen::Matrix3d LegJacobian(const LegGeometry& leg, const Eigen::Vector3d& q);

/// joint angles that put the foot at `p_H` (knee-backwards branch). unreachable targets
/// are projected onto the workspace first. returns true when `p_H` was reachable as given.
bool LegInverseKinematics(const LegGeometry& leg, const Eigen::Vector3d& p_H, Eigen::Vector3d* q);

}  // namespace penumbra
