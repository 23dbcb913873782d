#pragma once
// intensity multipliers of light events (definitions in types/light_event.h, LightEventParams).

#include <cstdint>

#include "penumbra/effects/effect_config.h"

namespace penumbra {

/// the multiplier s(t) in [0, 1] that a light event applies to its target light(s) at sim
/// time t, including the effect's time window: 1 outside [start_sec, stop_sec] (blackout:
/// plus the recovery ramp after stop_sec), and blended as 1 - w (1 - s) with the effect's
/// fade weight w (blackout: fade_in_sec dims down; the recovery replaces the fade out).
/// `key` identifies the effect's random streams (flicker noise, failing slots).
double LightEventScale(const EffectConfig& effect, double t, uint64_t key);

}  // namespace penumbra
