#pragma once
// what a controller may read at a control update: time and the state of the
// model, plus derived quantities (body poses, twists, Jacobians) computed on
// request. implemented by physics/simulation over MuJoCo; tests can fake it.

#include <Eigen/Core>
#include <span>

#include "penumbra/control/model_info.h"
#include "penumbra/core/pose.h"

namespace penumbra {

/// spatial velocity (twist) of a body frame: (angular, linear) stacked, both in
/// world coordinates; linear is the velocity of the body frame's origin.
using Twist = Eigen::Matrix<double, 6, 1>;

/// read-only view of the simulation state at the instant of a control update.
/// positions and velocities are consistent with qpos/qvel of the same instant
/// (physics runs its position and velocity stages before calling controllers).
/// valid only during Controller::Compute; do not keep references to it.
class ControlInput {
 public:
  virtual ~ControlInput() = default;

  /// the controllers' clock (s): simulation time since the last Simulation::ResetControllers
  /// (the `reset` command), i.e. simulation time in a run without one.
  virtual double time_sec() const = 0;
  /// the model the state belongs to.
  virtual const ModelInfo& model() const = 0;
  /// (nq) joint positions, MuJoCo qpos layout (free joint: x y z qw qx qy qz).
  virtual std::span<const double> qpos() const = 0;
  /// (nv) joint velocities, MuJoCo qvel layout (free joint: linear world, angular local).
  virtual std::span<const double> qvel() const = 0;
  /// (nsensordata) sensor values (position and velocity stage sensors are current;
  /// acceleration stage sensors, e.g. accelerometers, are from the previous step).
  virtual std::span<const double> sensordata() const = 0;

  /// (nv) MuJoCo qfrc_bias = C(q, qdot) qdot + g(q): the Coriolis, centrifugal and gravity
  /// generalized forces (N or N m per dof) at the current state, from MuJoCo's recursive
  /// Newton-Euler pass (mj_rne, Featherstone, "Rigid Body Dynamics Algorithms", 2008). adding
  /// it to joint torques compensates gravity and velocity-product terms. empty when the
  /// input cannot provide it (the default, e.g. hand-made fakes in tests).
  virtual std::span<const double> qfrc_bias() const { return {}; }

  /// X_WB: pose of body `body` (ModelInfo index) in the world frame.
  virtual Pose X_WB(int body) const = 0;
  /// V_WB: twist of body `body`'s frame in the world frame (see Twist).
  virtual Twist V_WB(int body) const = 0;
  /// J (6 x nv): maps qvel to the twist (angular, linear) of a frame fixed to `body`
  /// whose origin is at `p_W` (world coordinates, e.g. an end-effector point), as
  /// MuJoCo's mj_jac. resizes `J` if needed; no allocation once sized.
  virtual void Jacobian(int body, const Eigen::Vector3d& p_W,
                        Eigen::Matrix<double, 6, Eigen::Dynamic>* J) const = 0;
};

}  // namespace penumbra
