#include "penumbra/effects/types/wetness.h"

#include <algorithm>
#include <cmath>

#include "penumbra/effects/effect_config.h"
#include "penumbra/scene/scene_limits.h"

namespace penumbra {
namespace {

class WetnessInstance : public EffectInstance {
 public:
  WetnessInstance(const WetnessParams& p, const EffectConfig* rain) : wp_(p), rain_(rain) {}

  void Evaluate(const EffectEvalContext& ctx, EffectsFrame* frame) override {
    if (ctx.weight <= 0 || !rain_) return;
    const WetnessParams& wp = wp_;
    const double t = ctx.time_sec;
    const double a = rain_->start_sec, b = rain_->stop_sec;
    double wet = 0;
    if (t >= a && t <= b) {
      wet = 1 - std::exp(-(t - a) / wp.wetting_time_sec);
    } else if (t > b) {
      wet =
          (1 - std::exp(-(b - a) / wp.wetting_time_sec)) * std::exp(-(t - b) / wp.drying_time_sec);
    }
    frame->surface_wetness =
        std::max(frame->surface_wetness, static_cast<float>(wp.max_wetness * wet));
  }

 private:
  const WetnessParams& wp_;
  const EffectConfig* rain_;  // the rain effect followed (in the engine's list), or null
};

}  // namespace

std::vector<std::string_view> WetnessParams::Keys() {
  return {"rain", "wetting_time_sec", "drying_time_sec", "max_wetness"};
}

void WetnessParams::Read(const EffectParamReader& r) {
  r.Str("rain", &rain);
  r.Num("wetting_time_sec", &wetting_time_sec);
  r.Num("drying_time_sec", &drying_time_sec);
  r.Num("max_wetness", &max_wetness);
}

void WetnessParams::Validate(const EffectConfig&, EffectChecker* c) const {
  using R = EffectRange;
  c->In("wetting_time_sec", wetting_time_sec, R::OpenClosed(0, kMaxDurationSec));
  c->In("drying_time_sec", drying_time_sec, R::OpenClosed(0, kMaxDurationSec));
  c->In("max_wetness", max_wetness, R::Closed(0, 1));
}

std::unique_ptr<EffectInstance> WetnessParams::Bind(const EffectConfig&,
                                                    const EffectBindContext& ctx) const {
  const EffectConfig* followed = nullptr;
  for (const EffectConfig& o : ctx.effects) {
    if (o.Is<RainParams>() && (rain.empty() || o.name == rain)) {
      followed = &o;
      break;
    }
  }
  return std::make_unique<WetnessInstance>(*this, followed);
}

std::optional<EffectProblem> WetnessParams::CheckReferences(
    const std::vector<EffectConfig>& effects) const {
  const bool found = std::any_of(effects.begin(), effects.end(), [&](const EffectConfig& o) {
    return o.Is<RainParams>() && (rain.empty() || o.name == rain);
  });
  if (found) return std::nullopt;
  return EffectProblem{
      "rain", "no rain effect '" + rain + "'; expected the name of a rain effect of this world"};
}

}  // namespace penumbra
