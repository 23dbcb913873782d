#include "penumbra/effects/types/rain.h"

#include "penumbra/effects/effect_config.h"
#include "penumbra/effects/types/precipitation_instance.h"

namespace penumbra {

std::vector<std::string_view> RainParams::Keys() {
  return {"rate_mm_h",     "wind_m_s", "min_diameter_mm", "max_diameter_mm", "box_half_extents_m",
          "max_particles", "color",    "sheltered"};
}

void RainParams::Read(const EffectParamReader& r) {
  r.Num("rate_mm_h", &rate_mm_h);
  r.Vec("wind_m_s", &wind_m_s);
  r.Num("min_diameter_mm", &min_diameter_mm);
  r.Num("max_diameter_mm", &max_diameter_mm);
  r.Vec("box_half_extents_m", &box_half_extents_m);
  r.Int("max_particles", &max_particles);
  r.Vec("color", &color);
  r.Bool("sheltered", &sheltered);
}

void RainParams::Validate(const EffectConfig&, EffectChecker* c) const {
  using R = EffectRange;
  c->In("rate_mm_h", rate_mm_h, R::OpenClosed(0, 500));
  c->In3("wind_m_s", wind_m_s, R::Closed(-100, 100));
  c->In("min_diameter_mm", min_diameter_mm, R::ClosedOpen(0.1, 6));
  c->In("max_diameter_mm", max_diameter_mm, R::OpenClosed(0.1, 6));
  if (c->ok() && !(max_diameter_mm > min_diameter_mm)) {
    c->Fail("max_diameter_mm", EffectChecker::Num(max_diameter_mm) +
                                   " is out of range; expected > min_diameter_mm (" +
                                   EffectChecker::Num(min_diameter_mm) + ") and <= 6");
  }
  c->In3("box_half_extents_m", box_half_extents_m, R::OpenClosed(0, 1e3));
  c->In("max_particles", max_particles, R::Closed(1, 5e6));
  c->In3("color", color, R::Closed(0, 1));
}

std::unique_ptr<EffectInstance> RainParams::Bind(const EffectConfig& e,
                                                 const EffectBindContext& ctx) const {
  const uint64_t key = ctx.key;
  return std::make_unique<PrecipitationInstance>(
      [this, key] { return BuildRainTable(*this, key, 1); }, e.region ? &*e.region : nullptr);
}

}  // namespace penumbra
