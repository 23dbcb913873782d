#include "penumbra/control/multirotor_model.h"

#include <Eigen/Dense>
#include <cmath>
#include <sstream>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

std::string Fmt(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

// X_base_b at qpos0 when b is `base` or one of its descendants, else nullopt-like false.
bool PoseInBase(const ModelInfo& m, int base, int b, Pose* X_base_b) {
  Pose X = Pose::Identity();
  while (b != base) {
    if (b <= 0) return false;
    X = m.body_X_PB[b] * X;
    b = m.body_parent[b];
  }
  *X_base_b = X;
  return true;
}

}  // namespace

MultirotorModel BuildMultirotorModel(const ModelInfo& m, int base_body,
                                     const std::vector<int>& rotor_actuators,
                                     const std::vector<std::string>& rotor_keys,
                                     const ControllerContext& c) {
  auto fail = [&](const std::string& key, const std::string& problem) {
    throw ConfigError(c.file, c.line, c.key.empty() ? key : c.key + "." + key, problem);
  };
  const size_t nbody = m.body_names.size();
  if (m.body_mass.size() != nbody || m.body_inertia.size() != nbody ||
      m.body_X_PB.size() != nbody || m.body_X_BI.size() != nbody ||
      m.site_X_BS.size() != m.site_names.size())
    fail("base_body",
         "the model info has no mass properties or site frames; expected a model loaded by "
         "Simulation");

  MultirotorModel out;

  // subtree mass and centre of mass
  std::vector<int> bodies;
  std::vector<Pose> X_base;  // X_base_b of each subtree body
  for (int b = 0; b < static_cast<int>(nbody); ++b) {
    Pose X;
    if (PoseInBase(m, base_body, b, &X)) {
      bodies.push_back(b);
      X_base.push_back(X);
    }
  }
  double mass = 0;
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  for (size_t k = 0; k < bodies.size(); ++k) {
    const int b = bodies[k];
    mass += m.body_mass[b];
    moment += m.body_mass[b] * (X_base[k] * m.body_X_BI[b].translation());
  }
  if (!(mass > 0))
    fail("base_body", "body '" + m.body_names[base_body] +
                          "' and its descendants have no mass; expected the airframe's base body");
  out.mass_kg = mass;
  out.com_B = moment / mass;

  // inertia about the centre of mass (parallel-axis theorem)
  Eigen::Matrix3d J = Eigen::Matrix3d::Zero();
  for (size_t k = 0; k < bodies.size(); ++k) {
    const int b = bodies[k];
    const Eigen::Matrix3d R = X_base[k].linear() * m.body_X_BI[b].linear();
    const Eigen::Vector3d r = X_base[k] * m.body_X_BI[b].translation() - out.com_B;
    J += R * m.body_inertia[b].asDiagonal() * R.transpose();
    J += m.body_mass[b] * (r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose());
  }
  out.inertia_B = 0.5 * (J + J.transpose());

  // allocation matrix
  const int n = static_cast<int>(rotor_actuators.size());
  out.allocation.resize(4, n);
  for (int i = 0; i < n; ++i) {
    const ActuatorInfo& a = m.actuators[rotor_actuators[i]];
    const std::string& key = rotor_keys[i];
    if (a.site < 0)
      fail(key, "actuator '" + a.name +
                    "' does not act on a site; expected a rotor actuator with site=\"...\" "
                    "(thrust along the site's axis)");
    Pose X_bs;
    if (!PoseInBase(m, base_body, m.site_body[a.site], &X_bs))
      fail(key, "actuator '" + a.name + "' acts on site '" + m.site_names[a.site] +
                    "', which is not on body '" + m.body_names[base_body] +
                    "' or its descendants; expected a rotor of the airframe");
    if (!a.ctrl_limited || !(a.ctrl_range[0] >= 0 && a.ctrl_range[1] > a.ctrl_range[0]))
      fail(key, "actuator '" + a.name + "' has ctrl range [" + Fmt(a.ctrl_range[0]) + ", " +
                    Fmt(a.ctrl_range[1]) + (a.ctrl_limited ? "]" : "] but is not ctrllimited") +
                    "; expected ctrllimited=\"true\" and 0 <= min < max (thrust in N)");
    const Pose X_BS = X_bs * m.site_X_BS[a.site];
    const Eigen::Vector3d f_S(a.gear[0], a.gear[1], a.gear[2]);
    const Eigen::Vector3d t_S(a.gear[3], a.gear[4], a.gear[5]);
    const Eigen::Vector3d f = X_BS.linear() * f_S;
    const Eigen::Vector3d r = X_BS.translation() - out.com_B;
    const Eigen::Vector3d t = X_BS.linear() * t_S + r.cross(f);
    if (!(f.z() > 0.9 * f.norm()))
      fail(key, "actuator '" + a.name + "' pushes along (" + Fmt(f.x()) + ", " + Fmt(f.y()) + ", " +
                    Fmt(f.z()) +
                    ") in the base frame; expected thrust within 25 deg of the base's +z");
    out.allocation.col(i) << f.z(), t.x(), t.y(), t.z();
    out.min_thrust_n.push_back(a.ctrl_range[0]);
    out.max_thrust_n.push_back(a.ctrl_range[1]);
    out.rotor_position_B.push_back(X_BS.translation());
  }

  // thrust, roll, pitch and yaw must be independently controllable, and collective thrust
  // must load every rotor (the mixer shifts collective along B^+ e_thrust)
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(out.allocation);
  const Eigen::VectorXd sv = svd.singularValues();
  const double scale = out.allocation.cwiseAbs().maxCoeff();
  if (n < 4 || sv.size() < 4 || !(sv[3] > 1e-6 * scale)) {
    std::string names;
    for (int i = 0; i < n; ++i)
      names += (i ? ", '" : "'") + m.actuators[rotor_actuators[i]].name + "'";
    fail("rotor_actuators",
         "rotors " + names +
             " cannot produce independent collective thrust, roll, pitch and yaw torques "
             "(allocation rank < 4); expected at least 4 rotors around the centre of mass "
             "with propellers of both spin directions (gear torques of both signs)");
  }
  return out;
}

}  // namespace penumbra
