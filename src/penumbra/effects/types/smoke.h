#pragma once
// the `smoke` effect type: procedural noise advected by the wind, or a grid-fluid plume.

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string_view>
#include <vector>

#include "penumbra/effects/effect_type.h"
#include "penumbra/effects/types/fluid_params.h"

namespace penumbra {

/// smoke: `noise` = fBm value noise translated by the wind (stateless), `plume` = grid
/// fluid. needs a region (the noise volume / the fluid's box).
/// noise: density d = max(0, n - (1 - coverage)) / coverage * w with n the blend of two fBm
/// slices (Fbm3 of effects/value_noise.h at (p - wind t) / noise_scale_m) that changes
/// shape at evolution_per_s; extinction sigma_t = density_scale_per_m * d.
struct SmokeParams {
  static constexpr std::string_view kTypeName = "smoke";

  enum class Mode { kNoise, kPlume };
  Mode mode = Mode::kNoise;
  double density_scale_per_m = 2.0;       ///< sigma_t at density 1, 1/m, > 0
  Eigen::Vector3d albedo{0.6, 0.6, 0.6};  ///< [0, 1]
  double g = 0.0;                         ///< (-1, 1)
  Eigen::Vector3d wind_m_s{0.5, 0, 0};    ///< noise: translation speed; plume: inflow wind
  // noise mode
  int noise_resolution = 48;     ///< voxels along the longest region axis, [8, 256]
  double noise_scale_m = 1.0;    ///< feature size of the first octave, > 0
  int octaves = 4;               ///< [1, 8]
  double coverage = 0.5;         ///< fraction of the volume with smoke, [0, 1]
  double evolution_per_s = 0.1;  ///< rate the pattern changes shape, >= 0
  // plume mode
  FluidParams fluid;

  /// effect-type hooks (effects/effect_type.h).
  static std::vector<std::string_view> Keys();
  void Read(const EffectParamReader& r);
  void Validate(const EffectConfig& e, EffectChecker* c) const;
  /// a GridMedium over the region: the noise density at the time, or the fluid stepped to it
  /// (the fluid is keyed by the effect's random stream; noise voxel rows run on ctx.pool).
  std::unique_ptr<EffectInstance> Bind(const EffectConfig& e, const EffectBindContext& ctx) const;
  /// the fluid's dt_sec in plume mode, else nullopt.
  std::optional<double> FluidDtSec() const;
};

}  // namespace penumbra
