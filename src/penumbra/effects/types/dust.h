#pragma once
// the `dust` effect type: a coloured, absorbing homogeneous haze.

#include <Eigen/Core>
#include <memory>
#include <string_view>
#include <vector>

#include "penumbra/effects/effect_type.h"
#include "penumbra/effects/types/homogeneous.h"

namespace penumbra {

/// dust: a coloured, absorbing haze. the colour is the single-scattering albedo per
/// channel (blue absorbed more than red gives the brown cast of mineral dust). density
/// falls off with height as for fog.
struct DustParams {
  static constexpr std::string_view kTypeName = "dust";

  ExtinctionSpec extinction;                ///< required
  Eigen::Vector3d color{0.75, 0.55, 0.35};  ///< albedo per channel, [0, 1]
  double g = 0.6;                           ///< (-1, 1)
  double height_falloff_per_m = 0;          ///< >= 0
  double base_height_m = 0;                 ///< finite

  /// effect-type hooks (effects/effect_type.h).
  static std::vector<std::string_view> Keys();
  void Read(const EffectParamReader& r);
  void Validate(const EffectConfig& e, EffectChecker* c) const;
  /// one HomogeneousMedium in the effect's region while the weight is > 0.
  std::unique_ptr<EffectInstance> Bind(const EffectConfig& e, const EffectBindContext& ctx) const;
};

}  // namespace penumbra
