#include "penumbra/effects/types/sun.h"

#include <utility>

#include "penumbra/effects/effect_config.h"
#include "penumbra/effects/sun.h"

namespace penumbra {
namespace {

class SunInstance : public EffectInstance {
 public:
  SunInstance(const SunParams& p, std::vector<std::pair<int, Light>> directional_lights)
      : sp_(p), directional_lights_(std::move(directional_lights)) {}

  void Evaluate(const EffectEvalContext& ctx, EffectsFrame* frame) override {
    if (ctx.weight <= 0) return;
    const SunParams& sp = sp_;
    const double jd = JulianDay(sp.year, sp.month, sp.day, sp.time_utc_h) +
                      sp.time_scale * ctx.time_sec / 86400.0;
    const SunPosition pos = ComputeSunPosition(jd, sp.latitude_deg, sp.longitude_deg);
    frame->sun_direction_W = SunDirectionEnu(pos);
    frame->sky_luminance_scale *= static_cast<float>(TwilightSkyScale(pos.geometric_elevation_deg));
    // the scene's suns follow: same light, new direction, air-mass attenuated
    const double direct = DirectSunAttenuation(pos.elevation_deg);
    for (const auto& [index, light] : directional_lights_) {
      frame->light_intensity_scale[index] = 0.0f;
      if (direct <= 0) continue;
      Light sun = light;
      sun.body = 0;
      sun.mjcf_light = -1;
      sun.direction_B = -*frame->sun_direction_W;
      sun.intensity = static_cast<float>(light.intensity * direct);
      frame->extra_lights.push_back(sun);
    }
  }
  bool ScalesSceneLights() const override { return true; }

 private:
  const SunParams& sp_;
  std::vector<std::pair<int, Light>> directional_lights_;  // (scene index, light)
};

}  // namespace

std::vector<std::string_view> SunParams::Keys() {
  return {"latitude_deg", "longitude_deg", "year", "month", "day", "time_utc_h", "time_scale"};
}

void SunParams::Read(const EffectParamReader& r) {
  r.Num("latitude_deg", &latitude_deg);
  r.Num("longitude_deg", &longitude_deg);
  r.Int("year", &year);
  r.Int("month", &month);
  r.Int("day", &day);
  r.Num("time_utc_h", &time_utc_h);
  r.Num("time_scale", &time_scale);
}

void SunParams::Validate(const EffectConfig&, EffectChecker* c) const {
  using R = EffectRange;
  c->In("latitude_deg", latitude_deg, R::Closed(-90, 90));
  c->In("longitude_deg", longitude_deg, R::Closed(-180, 180));
  c->In("year", year, R::Closed(1900, 2100));
  c->In("month", month, R::Closed(1, 12));
  if (c->ok()) {
    static const int kDays[12] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
    const bool leap = (year % 4 == 0 && year % 100 != 0) || year % 400 == 0;
    const int dim = kDays[month - 1] + (month == 2 && leap ? 1 : 0);
    c->In("day", day, R::Closed(1, dim));
  }
  c->In("time_utc_h", time_utc_h, R::ClosedOpen(0, 24));
  c->In("time_scale", time_scale, R::Closed(0, 1e6));
}

std::unique_ptr<EffectInstance> SunParams::Bind(const EffectConfig&,
                                                const EffectBindContext& ctx) const {
  std::vector<std::pair<int, Light>> directional;
  for (size_t l = 0; l < ctx.scene.lights.size(); ++l) {
    if (ctx.scene.lights[l].type == Light::Type::kDirectional) {
      directional.emplace_back(static_cast<int>(l), ctx.scene.lights[l]);
    }
  }
  return std::make_unique<SunInstance>(*this, std::move(directional));
}

}  // namespace penumbra
