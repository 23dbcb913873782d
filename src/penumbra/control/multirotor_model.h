#pragma once
// the rigid-body and rotor description a multirotor controller needs, derived from the
// compiled model (ModelInfo), so that one controller flies any rotor layout its MJCF
// describes: total mass, the centre of mass and inertia of the airframe, and the
// allocation matrix that maps per-rotor thrusts to collective thrust and body torques.
//
// rotor convention: each rotor is one actuator with a site transmission whose scalar force
// is its thrust in N (ctrl = thrust for a <motor> or a <general> with gain 1 and no bias,
// with or without filter dynamics). the actuator's gear (f_S, t_S) (site frame) gives the
// force and torque per newton of thrust: force along the rotor axis and the propeller's
// reaction torque -+k_m about it, e.g. gear="0 0 1 0 0 -0.016" for a counter-clockwise
// propeller. the allocation column of rotor i, in the base frame B about the centre of mass c:
//   f_i = R_BS f_S,   tau_i = R_BS t_S + (p_BS - c) x f_i,   column = (f_i.z, tau_i.x, tau_i.y,
//   tau_i.z)
// (e.g. R. Mahony, V. Kumar, P. Corke, "Multirotor Aerial Vehicles", IEEE Robotics &
// Automation Magazine 19(3), 2012, eq. 3-4, generalised to any rotor pose).
//
// mass properties: the bodies of the subtree rooted at the base body, at qpos0 (joints
// inside the subtree, e.g. a camera gimbal, are taken at their reference position):
//   m = sum m_b,  c = sum m_b c_b / m,
//   J = sum R_b I_b R_b^T + m_b (|r_b|^2 1 - r_b r_b^T),  r_b = c_b - c   (parallel-axis theorem).

#include <Eigen/Core>
#include <vector>

#include "penumbra/control/controller.h"
#include "penumbra/control/model_info.h"

namespace penumbra {

/// mass properties and rotor allocation of a multirotor, in its base body frame B.
struct MultirotorModel {
  double mass_kg = 0;                                       ///< subtree mass of the base body
  Eigen::Vector3d com_B = Eigen::Vector3d::Zero();          ///< centre of mass in B (m)
  Eigen::Matrix3d inertia_B = Eigen::Matrix3d::Identity();  ///< about the COM, B axes (kg m^2)
  /// (4 x n) wrench per newton of each rotor's thrust: rows thrust along B's z (N), torque
  /// about B's x, y, z through the COM (N m); column i is rotor i in config order.
  Eigen::Matrix<double, 4, Eigen::Dynamic> allocation;
  std::vector<double> min_thrust_n;               ///< (n) lower ctrl limit of each rotor (N)
  std::vector<double> max_thrust_n;               ///< (n) upper ctrl limit of each rotor (N)
  std::vector<Eigen::Vector3d> rotor_position_B;  ///< (n) site origins in B (m), for reports

  /// number of rotors.
  int num_rotors() const { return static_cast<int>(allocation.cols()); }
};

/// builds the MultirotorModel of the subtree rooted at `base_body` with rotors
/// `rotor_actuators` (model indices, in order). `rotor_keys` names the config key of each
/// rotor (e.g. "rotor_actuators[2]") for messages.
/// @throws ConfigError (in `context`) if the model info lacks mass properties (hand-made
///         ModelInfo), the subtree is massless, a rotor actuator has no site transmission,
///         its site is not on the base body's subtree, its ctrl is not limited to a range
///         [min, max] with 0 <= min < max, its thrust does not point along +z of the base,
///         or the rotors cannot produce independent thrust, roll, pitch and yaw torques
///         (allocation rank < 4).
MultirotorModel BuildMultirotorModel(const ModelInfo& model, int base_body,
                                     const std::vector<int>& rotor_actuators,
                                     const std::vector<std::string>& rotor_keys,
                                     const ControllerContext& context);

}  // namespace penumbra
