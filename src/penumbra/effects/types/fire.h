#pragma once
// the `fire` effect type: a grid-fluid flame with blackbody emission and a glow light.

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string_view>
#include <vector>

#include "penumbra/effects/effect_type.h"
#include "penumbra/effects/types/fluid_params.h"

namespace penumbra {

/// fire: a grid-fluid flame (FluidParams, emitters at temperature_k ~ 1200-1800 K) in the
/// effect's region (required).
/// emission per unit length j = absorption_per_m * density * L_bb(T) in the colour of
/// BlackbodyLinearSrgb(T), L_bb = blackbody luminance (blackbody.h); extinction
/// sigma_t = density_scale_per_m * density (soot). the glow is also added as a point
/// light in extra_lights at the emission centroid with intensity
///   I = sum_voxels j_Y dV  (cd)   (optically thin: luminous flux 4 pi sum j_Y dV over 4 pi sr),
/// coloured by the emission-weighted mean colour c (max component 1), stored as
/// Light::intensity = I / Y(c) since the renderer multiplies intensity by the tint. the
/// light follows the fire's emitted power, so it flickers with the flame.
struct FireParams {
  static constexpr std::string_view kTypeName = "fire";

  FluidParams fluid;
  double density_scale_per_m = 1.0;         ///< soot extinction at density 1, > 0
  double absorption_per_m = 2.0;            ///< emitting absorption at density 1, > 0
  Eigen::Vector3d albedo{0.2, 0.2, 0.2};    ///< soot albedo, [0, 1]
  double min_emission_temperature_k = 800;  ///< voxels below emit nothing, [300, 4000]
  bool glow_light = true;                   ///< add the point light
  double glow_light_radius_m = 0.1;         ///< >= 0

  /// effect-type hooks (effects/effect_type.h).
  static std::vector<std::string_view> Keys();
  void Read(const EffectParamReader& r);
  void Validate(const EffectConfig& e, EffectChecker* c) const;
  std::unique_ptr<EffectInstance> Bind(const EffectConfig& e, const EffectBindContext& ctx) const;
  /// the fluid's dt_sec.
  std::optional<double> FluidDtSec() const { return fluid.dt_sec; }
};

}  // namespace penumbra
