#pragma once
// MuJoCo 3 and 4 <option> settings that serve robots, beyond the integrator, gravity, solver
// iterations and friction cone every composition sets (physics/model_spec_composer.h
// SpecOptionOverrides): the NoSlip post-solver (MuJoCo XML reference, option
// noslip_iterations) and MuJoCo 4.0's speculative contacts (option/flag speculative). applied
// to an mjOption: a world spec's (mjSpec::option) before it compiles, so that composed.xml
// carries them and a replay of it steps the same, or a compiled model's (mjModel::opt).
// docs/physics-mujoco4.md lists what else MuJoCo 3 and 4 added and why it is not a setting.

#include <optional>

struct mjOption_;

namespace penumbra {

/// the largest noslip_iterations accepted (MuJoCo's own default is 0 = off; a few to tens of
/// iterations remove the creep of soft contacts).
inline constexpr int kMaxNoslipIterations = 1000;

/// contact settings newer than MuJoCo 2.2.2's <option> that a world may set; unset keeps the
/// models' own <option>.
struct ContactOptions {
  /// <option noslip_iterations>: iterations of MuJoCo's NoSlip post-solver after the main
  /// solver, in [0, kMaxNoslipIterations]; 0 = off. removes the slow slip of soft contacts
  /// (grasped objects, robots standing on slopes) at the cost of a PGS pass per step.
  std::optional<int> noslip_iterations;
  /// <option><flag speculative>: contacts for fast convex geoms before they touch, so that
  /// they do not tunnel through thin obstacles within one step (MuJoCo 4.0).
  std::optional<bool> speculative;

  bool empty() const { return !noslip_iterations && !speculative; }
};

/// sets the fields of `opt` that `options` sets and leaves the rest.
/// @throws ConfigError("", 0, "physics.noslip_iterations", ...) for a value outside
///         [0, kMaxNoslipIterations] (opt unchanged).
void ApplyContactOptions(const ContactOptions& options, mjOption_* opt);

}  // namespace penumbra
