#pragma once
// the `rain` effect type: Marshall-Palmer drops around the viewer.

#include <Eigen/Core>
#include <memory>
#include <string_view>
#include <vector>

#include "penumbra/effects/effect_type.h"

namespace penumbra {

/// rain after Marshall & Palmer, "The distribution of raindrops with size", J. Meteor. 5,
/// 1948: N(D) = N0 exp(-Lambda D), N0 = 8000 m^-3 mm^-1, Lambda = 4.1 R^-0.21 mm^-1
/// (R in mm/h), truncated to [min_diameter_mm, max_diameter_mm] (drops below 0.1 mm are
/// drizzle/mist, above 6 mm they break up). terminal velocity: Atlas, Srivastava, Sekhon,
/// Rev. Geophys. 11, 1973, v(D) = 9.65 - 10.3 exp(-0.6 D) m/s (D in mm), a fit of the
/// measurements of Gunn & Kinzer, J. Meteor. 6, 1949 (clamped at >= 0). the drops fill a
/// periodic box around the viewer (effects/precipitation.h), only inside the effect's
/// region when it has one.
struct RainParams {
  static constexpr std::string_view kTypeName = "rain";

  double rate_mm_h = 5;               ///< (0, 500]
  Eigen::Vector3d wind_m_s{0, 0, 0};  ///< horizontal wind added to every drop (z ignored)
  double min_diameter_mm = 0.1;       ///< [0.1, 6)
  double max_diameter_mm = 6.0;       ///< (min, 6]
  /// half size of the box around the viewer that is filled with drops, m, each > 0.
  Eigen::Vector3d box_half_extents_m{4, 4, 3};
  /// cap on the drop count; when the box would hold more, it is shrunk uniformly so the
  /// number density is kept. [1, 5e6]
  int max_particles = 200000;
  Eigen::Vector3d color{0.85, 0.9, 1.0};  ///< drop tint (albedo), [0, 1]
  /// true: no drop is drawn under static geometry (a roof; render/particles/shelter_map.h); false:
  /// drops fall everywhere, indoors too (a leaking roof, a sprinkler).
  bool sheltered = true;

  /// effect-type hooks (effects/effect_type.h).
  static std::vector<std::string_view> Keys();
  void Read(const EffectParamReader& r);
  void Validate(const EffectConfig& e, EffectChecker* c) const;
  std::unique_ptr<EffectInstance> Bind(const EffectConfig& e, const EffectBindContext& ctx) const;
};

}  // namespace penumbra
