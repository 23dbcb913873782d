#pragma once
// the `dust` effect type: a coloured, absorbing homogeneous haze.

#include <Eigen/Core>
#include <optional>
#include <string_view>

#include "penumbra/effects/effect_type.h"
#include "penumbra/effects/types/homogeneous.h"

namespace penumbra {

/// dust: a coloured, absorbing haze. the colour is the single-scattering albedo per
/// channel (blue absorbed more than red gives the brown cast of mineral dust). density
/// falls off with height as for fog.
struct DustParams : HomogeneousMediumType<DustParams> {
  static constexpr std::string_view kTypeName = "dust";

  ExtinctionSpec extinction;                ///< required
  Eigen::Vector3d color{0.75, 0.55, 0.35};  ///< albedo per channel, [0, 1]
  double g = 0.6;                           ///< (-1, 1)
  double height_falloff_per_m = 0;          ///< >= 0
  double base_height_m = 0;                 ///< finite
  /// without a region: world z (m) of the top of the layer the medium fills (unbounded in x,
  /// y and downwards); the sun and sky cross only the part of their path below it. nullopt =
  /// the top of the model's bounding sphere (SceneDescription::center_W.z + extent_m).
  std::optional<double> layer_top_m;

  /// the albedo's world-file key and field; the hooks are HomogeneousMediumType's.
  static constexpr std::string_view kAlbedoKey = "color";
  static constexpr Eigen::Vector3d DustParams::*kAlbedo = &DustParams::color;
};

}  // namespace penumbra
