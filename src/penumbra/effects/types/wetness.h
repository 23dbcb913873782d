#pragma once
// the `wetness` effect type: surface wetness that follows a rain effect.

#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "penumbra/effects/effect_type.h"

namespace penumbra {

/// wetness after rain: w rises as 1 - exp(-t / wetting_time_sec) while the rain effect is
/// active (from its start_sec to its stop_sec) and decays as exp(-t / drying_time_sec)
/// after it stops; scaled by max_wetness into EffectsFrame::surface_wetness (the largest
/// of several wetness effects wins).
struct WetnessParams {
  static constexpr std::string_view kTypeName = "wetness";

  std::string rain;              ///< name of the rain effect; "" = the first rain effect
  double wetting_time_sec = 60;  ///< > 0
  double drying_time_sec = 600;  ///< > 0
  double max_wetness = 1;        ///< [0, 1]

  /// effect-type hooks (effects/effect_type.h).
  static std::vector<std::string_view> Keys();
  void Read(const EffectParamReader& r);
  void Validate(const EffectConfig& e, EffectChecker* c) const;
  std::unique_ptr<EffectInstance> Bind(const EffectConfig& e, const EffectBindContext& ctx) const;
  /// `rain` must name a rain effect of the run ("" = there must be one); problem at key "rain".
  std::optional<EffectProblem> CheckReferences(const std::vector<EffectConfig>& effects) const;
};

}  // namespace penumbra
