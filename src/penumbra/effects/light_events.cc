#include "penumbra/effects/light_events.h"

#include <algorithm>
#include <cmath>

#include "penumbra/core/rng.h"
#include "penumbra/effects/value_noise.h"

namespace penumbra {

double LightEventScale(const EffectConfig& e, double t, uint64_t key) {
  const LightEventParams& p = e.Get<LightEventParams>();
  if (p.mode == LightEventParams::Mode::kBlackout) {
    if (t < e.start_sec) return 1.0;
    if (t <= e.stop_sec) {
      const double w =
          e.fade_in_sec > 0 ? std::clamp((t - e.start_sec) / e.fade_in_sec, 0.0, 1.0) : 1.0;
      return 1.0 - w * (1.0 - p.min_scale);
    }
    if (p.recovery_sec <= 0) return 1.0;
    const double r = std::clamp((t - e.stop_sec) / p.recovery_sec, 0.0, 1.0);
    return p.min_scale + (1.0 - p.min_scale) * r;
  }
  const double w = e.Weight(t);
  if (w <= 0) return 1.0;
  const double local = t - e.start_sec;
  double s = 1.0;
  switch (p.mode) {
    case LightEventParams::Mode::kFlicker:
      s = 1.0 - p.depth * ValueNoise1(HashKeys(key, 1), local * p.frequency_hz);
      break;
    case LightEventParams::Mode::kFailing: {
      const int64_t slot = static_cast<int64_t>(std::floor(local * p.frequency_hz));
      const bool off = LatticeValue(HashKeys(key, 2), slot) < p.failure_probability;
      s = off ? p.min_scale
              : 1.0 - 0.5 * p.depth * ValueNoise1(HashKeys(key, 1), local * p.frequency_hz);
      break;
    }
    case LightEventParams::Mode::kStrobe: {
      const double phase = local * p.frequency_hz - std::floor(local * p.frequency_hz);
      s = phase < p.duty_cycle ? 1.0 : p.min_scale;
      break;
    }
    case LightEventParams::Mode::kBlackout:
      break;
  }
  return 1.0 - w * (1.0 - s);
}

}  // namespace penumbra
