#include "penumbra/effects/types/light_event.h"

#include "penumbra/core/error.h"
#include "penumbra/effects/effect_config.h"
#include "penumbra/effects/light_events.h"
#include "penumbra/scene/scene_limits.h"

namespace penumbra {
namespace {

class LightEventInstance : public EffectInstance {
 public:
  LightEventInstance(const EffectConfig& e, uint64_t key, std::vector<int> lights)
      : e_(e), key_(key), lights_(std::move(lights)) {}

  void Evaluate(const EffectEvalContext& ctx, EffectsFrame* frame) override {
    const float s = static_cast<float>(LightEventScale(e_, ctx.time_sec, key_));
    for (int l : lights_) frame->light_intensity_scale[l] *= s;
  }
  bool ScalesSceneLights() const override { return true; }

 private:
  const EffectConfig& e_;
  uint64_t key_;
  std::vector<int> lights_;  // indices of the target scene lights
};

}  // namespace

std::vector<std::string_view> LightEventParams::Keys() {
  return {"light",     "mode",        "frequency_hz", "depth", "duty_cycle", "failure_probability",
          "min_scale", "recovery_sec"};
}

void LightEventParams::Read(const EffectParamReader& r) {
  light = r.String("light");
  if (r.Has("mode")) {
    const std::string m = r.Enum("mode", {"flicker", "failing", "strobe", "blackout"});
    mode = m == "flicker"   ? Mode::kFlicker
           : m == "failing" ? Mode::kFailing
           : m == "strobe"  ? Mode::kStrobe
                            : Mode::kBlackout;
  }
  r.Num("frequency_hz", &frequency_hz);
  r.Num("depth", &depth);
  r.Num("duty_cycle", &duty_cycle);
  r.Num("failure_probability", &failure_probability);
  r.Num("min_scale", &min_scale);
  r.Num("recovery_sec", &recovery_sec);
}

void LightEventParams::Validate(const EffectConfig&, EffectChecker* c) const {
  using R = EffectRange;
  if (light.empty()) {
    c->Fail("light", "no target light; expected a scene light name or \"*\"");
  }
  c->In("frequency_hz", frequency_hz, R::OpenClosed(0, 1000));
  c->In("depth", depth, R::Closed(0, 1));
  c->In("duty_cycle", duty_cycle, R::Open(0, 1));
  c->In("failure_probability", failure_probability, R::Closed(0, 1));
  c->In("min_scale", min_scale, R::ClosedOpen(0, 1));
  c->In("recovery_sec", recovery_sec, R::Closed(0, kMaxDurationSec));
}

std::unique_ptr<EffectInstance> LightEventParams::Bind(const EffectConfig& e,
                                                       const EffectBindContext& ctx) const {
  const std::vector<Light>& scene_lights = ctx.scene.lights;
  std::vector<int> lights;
  std::string names;
  for (size_t l = 0; l < scene_lights.size(); ++l) {
    if (light == "*" || scene_lights[l].name == light) lights.push_back(static_cast<int>(l));
    names += (names.empty() ? "" : ", ") + scene_lights[l].name;
  }
  if (lights.empty() && light != "*") {
    throw ConfigError("", 0, ctx.key_prefix + ".light",
                      ctx.who + "no scene light named '" + light +
                          "' (lights: " + (names.empty() ? "none" : names) +
                          "); expected a light name of the scene or \"*\"");
  }
  return std::make_unique<LightEventInstance>(e, ctx.key, std::move(lights));
}

}  // namespace penumbra
