#pragma once
// the `fog` effect type: a homogeneous scattering medium with optional height falloff.

#include <Eigen/Core>
#include <optional>
#include <string_view>

#include "penumbra/effects/effect_type.h"
#include "penumbra/effects/types/homogeneous.h"

namespace penumbra {

/// fog: sigma_t(p) = sigma_t * exp(-height_falloff_per_m * max(0, p.z - base_height_m)).
struct FogParams : HomogeneousMediumType<FogParams> {
  static constexpr std::string_view kTypeName = "fog";

  ExtinctionSpec extinction;                 ///< required (sigma_t_per_m or mor_m)
  Eigen::Vector3d albedo{0.95, 0.95, 0.95};  ///< single-scattering albedo per channel, [0, 1]
  double g = 0.8;  ///< Henyey-Greenstein asymmetry, (-1, 1); water fog is strongly forward (~0.8)
  double height_falloff_per_m = 0;  ///< >= 0, 0 = uniform
  double base_height_m = 0;         ///< finite; full density below this height
  /// without a region: world z (m) of the top of the layer the medium fills (unbounded in x,
  /// y and downwards); the sun and sky cross only the part of their path below it. nullopt =
  /// the top of the model's bounding sphere (SceneDescription::center_W.z + extent_m).
  std::optional<double> layer_top_m;

  /// the albedo's world-file key and field; the hooks are HomogeneousMediumType's.
  static constexpr std::string_view kAlbedoKey = "albedo";
  static constexpr Eigen::Vector3d FogParams::*kAlbedo = &FogParams::albedo;
};

}  // namespace penumbra
