#pragma once
// optimal reciprocal collision avoidance (ORCA) for discs in the plane: J. van den Berg,
// S. J. Guy, M. Lin, D. Manocha, "Reciprocal n-Body Collision Avoidance", Robotics Research
// (ISRR 2009), Springer STAR 70, 2011, pp. 3-19. written from the paper (sections 4 and 5):
//   - for agent A and neighbour B (relative position p = p_B - p_A, relative velocity
//     v = v_A - v_B, combined radius r, time horizon tau), the velocity obstacle VO is the
//     cone from the origin over the disc D(p / tau, r / tau), truncated by that disc. u is the
//     smallest change of v that leaves VO (to the closest point of its boundary), n the
//     boundary's outward normal there. the ORCA half-plane of A is
//     { v' : (v' - (v_A + w u)) . n >= 0 } with w = 1/2 when B avoids too, 1 when A avoids
//     alone (the robot, or a vehicle that keeps to its lane). when A and B already overlap,
//     the disc is D(p / dt, r / dt) for the time step dt, which separates them in one step.
//   - the new velocity is the point of the intersection of the half-planes and the disc of
//     radius v_max closest to the preferred velocity: a 2-d linear program solved
//     incrementally (each constraint in turn; when the optimum so far violates it, the new
//     optimum lies on its line: a 1-d program against the earlier constraints). the order is
//     the given one (deterministic), not a random permutation.
//   - when the program is infeasible (dense crowds), the velocity that minimises the largest
//     violation of any half-plane, a 3-d program solved the same way (section 5.2).
// units: m, s, m/s; world xy.

#include <Eigen/Core>
#include <vector>

namespace penumbra {

/// a half-plane of admissible velocities: { v : det(direction, v - point) >= 0 }, i.e. the
/// side to the left of `direction` (a unit vector) through `point`.
struct OrcaLine {
  Eigen::Vector2d point{0, 0};
  Eigen::Vector2d direction{1, 0};
};

/// the ORCA half-plane of an agent at p_a with velocity v_a against a disc neighbour.
/// @param rel_position     p_b - p_a, m
/// @param rel_velocity     v_a - v_b, m/s
/// @param combined_radius  r_a + r_b (plus any clearance), m (> 0)
/// @param tau              time horizon, s (> 0)
/// @param dt               time step, s (> 0), used when the discs already overlap
/// @param responsibility   w: 0.5 reciprocal, 1 when the agent avoids alone
OrcaLine OrcaHalfPlane(const Eigen::Vector2d& v_a, const Eigen::Vector2d& rel_position,
                       const Eigen::Vector2d& rel_velocity, double combined_radius, double tau,
                       double dt, double responsibility);

/// the admissible velocity (|v| <= max_speed, inside every half-plane) closest to
/// `preferred`; when none exists, the velocity of speed <= max_speed that minimises the
/// largest distance by which it lies outside a half-plane (the paper's 3-d program).
/// deterministic: constraints are taken in the given order.
Eigen::Vector2d SolveOrcaVelocity(const std::vector<OrcaLine>& lines, double max_speed,
                                  const Eigen::Vector2d& preferred);

}  // namespace penumbra
