#pragma once
// the `light_event` effect type: flicker / failing / strobe / blackout of scene lights.

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "penumbra/effects/effect_type.h"

namespace penumbra {

/// light_event: changes the intensity multiplier of the scene light named `light` ("*" =
/// every light of the scene); several events on one light multiply. the multiplier
/// s(t) is computed by LightEventScale (effects/light_events.h):
///  flicker: s = 1 - depth * n(t), n = smooth value noise in [0, 1] at frequency_hz.
///  failing: time is cut into slots of 1 / frequency_hz; a slot is off (s = min_scale)
///           with probability failure_probability, else s = 1 - 0.5 depth n(t).
///  strobe:  s = 1 while frac((t - start_sec) frequency_hz) < duty_cycle, else min_scale.
///  blackout: s = min_scale in [start, stop], then a linear ramp to 1 over recovery_sec.
struct LightEventParams {
  static constexpr std::string_view kTypeName = "light_event";

  enum class Mode { kFlicker, kFailing, kStrobe, kBlackout };
  std::string light;  ///< scene light name or "*", required
  Mode mode = Mode::kFlicker;
  double frequency_hz = 8;           ///< (0, 1000]
  double depth = 0.5;                ///< [0, 1]
  double duty_cycle = 0.5;           ///< (0, 1)
  double failure_probability = 0.3;  ///< [0, 1]
  double min_scale = 0;              ///< [0, 1)
  double recovery_sec = 2;           ///< >= 0 (blackout)

  /// effect-type hooks (effects/effect_type.h).
  static std::vector<std::string_view> Keys();
  void Read(const EffectParamReader& r);
  void Validate(const EffectConfig& e, EffectChecker* c) const;
  /// @throws ConfigError("", 0, "effects[i].light", ...) when no scene light has that name
  ///         (the message lists the scene's lights).
  std::unique_ptr<EffectInstance> Bind(const EffectConfig& e, const EffectBindContext& ctx) const;
};

}  // namespace penumbra
