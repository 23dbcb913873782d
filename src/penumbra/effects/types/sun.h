#pragma once
// the `sun` effect type: sun direction and sky level from date, time and place.

#include <memory>
#include <string_view>
#include <vector>

#include "penumbra/effects/effect_type.h"

namespace penumbra {

/// sun: sun position from the NOAA solar calculator equations (after Meeus, "Astronomical
/// Algorithms", 1991; accuracy ~0.01 deg for 1800-2100; effects/sun.h). world x = east,
/// y = north, z = up. the clock runs at time_scale x sim time from the given start. below
/// the horizon the sky is scaled by a twilight model (sun.h). the scene's directional
/// lights follow the sun (EffectsEngine::Evaluate).
struct SunParams {
  static constexpr std::string_view kTypeName = "sun";

  double latitude_deg = 48.14;   ///< [-90, 90], north positive
  double longitude_deg = 11.58;  ///< [-180, 180], east positive
  int year = 2024;               ///< [1900, 2100]
  int month = 6;                 ///< [1, 12]
  int day = 21;                  ///< [1, days in month]
  double time_utc_h = 12;        ///< hours UTC at sim time 0, [0, 24)
  double time_scale = 1;         ///< clock seconds per sim second, [0, 1e6] (60 = 1 h per minute)

  /// effect-type hooks (effects/effect_type.h).
  static std::vector<std::string_view> Keys();
  void Read(const EffectParamReader& r);
  void Validate(const EffectConfig& e, EffectChecker* c) const;
  std::unique_ptr<EffectInstance> Bind(const EffectConfig& e, const EffectBindContext& ctx) const;
};

}  // namespace penumbra
