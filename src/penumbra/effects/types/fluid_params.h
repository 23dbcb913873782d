#pragma once
// parameters of the grid fluid (effects/grid_fluid.h) shared by the smoke (plume mode) and
// fire effect types, with their world-file reader and checks.

#include <Eigen/Core>
#include <optional>
#include <string_view>
#include <vector>

#include "penumbra/effects/effect_type.h"
#include "penumbra/scene/effects_frame.h"

namespace penumbra {

/// one smoke / fire source of the grid fluid.
struct PlumeEmitter {
  Eigen::Vector3d position_W{0, 0, 0};  ///< centre, world frame, must lie inside the region
  double radius_m = 0.2;  ///< (0, 1e5]; voxels whose centres are within it receive the source
  /// mass injected per second (density x m^3 per s), [0, 1000]. density 1 = sigma_t of
  /// density_scale.
  double rate = 0.5;
  /// temperature of the injected gas, K, [300, 4000] (fire: drives emission and buoyancy).
  double temperature_k = 600;
};

/// grid fluid after Stam, "Stable Fluids", SIGGRAPH 1999 (semi-Lagrangian advection,
/// pressure projection by Jacobi iterations) with the buoyancy of Fedkiw, Stam, Jensen,
/// "Visual Simulation of Smoke", SIGGRAPH 2001: f_z = buoyancy_m_s2 * (T - T_amb) / T_amb
/// - weight_m_s2 * density.
struct FluidParams {
  int resolution = 48;  ///< voxels along the longest region axis, [8, 128]
  /// range of dt_sec: the state at time t takes floor(t / dt_sec) steps from t = 0, so the
  /// lower end caps the work at 1000 steps per simulated second (cost per step in
  /// docs/effects.md) instead of letting a tiny step hang the run.
  static constexpr double kMinDtSec = 1e-3, kMaxDtSec = 0.1;
  double dt_sec = 1.0 / 30.0;  ///< fixed internal step, [kMinDtSec, kMaxDtSec]
  int jacobi_iterations = 20;  ///< pressure iterations per step, [1, 200]
  /// largest buoyancy_m_s2 / weight_m_s2 (100 g) and largest rate of an emitter, of
  /// dissipation and of cooling (per s).
  static constexpr double kMaxFluidAccelerationM_S2 = 1000;
  static constexpr double kMaxFluidRatePerS = 1000;
  double buoyancy_m_s2 = 9.81;            ///< [0, 1000], thermal buoyancy scale
  double weight_m_s2 = 0.0;               ///< [0, 1000], downward pull per unit density
  double dissipation_per_s = 0.1;         ///< density decay rate k (d rho/dt = -k rho), [0, 1000]
  double cooling_per_s = 1.5;             ///< temperature excess decay rate, [0, 1000]
  double ambient_temperature_k = 293.15;  ///< [200, 400]
  /// random horizontal velocity kick per step at each emitter, uniform in [-t, t] m/s per
  /// axis from the seed (breaks the symmetry, makes flames flicker), [0, 20].
  double turbulence_m_s = 0.5;
  std::vector<PlumeEmitter> emitters;  ///< at least one

  /// the world-file keys of the fluid (next to the effect's own keys).
  static std::vector<std::string_view> Keys();
  /// reads the keys present; `emitters` replaces the list, each element a map of
  /// position (required), radius_m, rate, temperature_k.
  void Read(const EffectParamReader& r);
  /// ranges; every emitter must lie inside `region` (when given).
  void Validate(const std::optional<BoxRegion>& region, EffectChecker* c) const;
};

}  // namespace penumbra
