#pragma once
// ground reaction forces for the stance feet of a legged robot that produce a desired
// wrench on its centre of mass: the "virtual model" / quasi-static balance controller of
// C. Gehring et al., "Control of Dynamic Gaits for a Quadrupedal Robot", ICRA 2013, and
// G. Bledt et al., "MIT Cheetah 3", IROS 2018, solved QP-free:
//
//   A f = w,   A = [ I       I     ... ],   w = (F, tau)   (world frame, about the COM)
//                  [ [r_1]x  [r_2]x ... ]
//   f* = argmin |A f - w|^2_S + alpha |f|^2 = (A^T S A + alpha I)^-1 A^T S w
//      = A^T S^1/2 (alpha I + S^1/2 A A^T S^1/2)^-1 S^1/2 w     (a 6 x 6 solve),
//   S = diag(1, 1, 1, s_tau, s_tau, s_tau),
//
// with r_i the foot positions relative to the COM and swing feet's forces fixed at zero;
// then each force is projected into its friction cone about the ground normal n:
// f_n = clamp(f . n, f_min, f_max), tangential part scaled down to |f_t| <= mu f_n.
// the projection can leave the wrench partly unmet; that is the price of skipping a QP
// (Di Carlo et al., "Dynamic Locomotion in the MIT Cheetah 3 Through Convex Model-Predictive
// Control", IROS 2018, solve the constrained problem exactly).

#include <Eigen/Core>
#include <array>

namespace penumbra {

/// weights and limits of DistributeStanceForces.
struct StanceForceLimits {
  double mu = 0.6;               ///< friction coefficient used for the cone (< the real one)
  double min_normal_n = 1.0;     ///< lower bound of each stance foot's normal force (N)
  double max_normal_n = 1e3;     ///< upper bound of each stance foot's normal force (N)
  double torque_weight = 10.0;   ///< s_tau: weight of the moment rows relative to the force rows
  double regularization = 1e-3;  ///< alpha: penalty on |f|^2 (keeps the solution unique)
};

/// forces on the robot at its four feet (world frame, N) for the desired wrench
/// `wrench` = (force (N), moment about the COM (N m)), world frame.
/// @param r_W      foot positions relative to the COM (world frame, m)
/// @param stance   which feet are on the ground; the others get zero force
/// @param normal_W unit ground normal (world frame) for the friction cones
/// @param forces   out: force on the robot at each foot (zero for swing feet)
void DistributeStanceForces(const std::array<Eigen::Vector3d, 4>& r_W,
                            const std::array<bool, 4>& stance,
                            const Eigen::Matrix<double, 6, 1>& wrench,
                            const Eigen::Vector3d& normal_W, const StanceForceLimits& limits,
                            std::array<Eigen::Vector3d, 4>* forces);

}  // namespace penumbra
