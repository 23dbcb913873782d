#include "penumbra/effects/types/snow.h"

#include "penumbra/effects/effect_config.h"
#include "penumbra/effects/types/precipitation_instance.h"

namespace penumbra {

std::vector<std::string_view> SnowParams::Keys() {
  return {"rate_mm_h",          "flake_diameter_mm", "flake_density_kg_m3",
          "wind_m_s",           "turbulence_m_s",    "drift_frequency_hz",
          "box_half_extents_m", "max_particles",     "color",
          "sheltered"};
}

void SnowParams::Read(const EffectParamReader& r) {
  r.Num("rate_mm_h", &rate_mm_h);
  r.Num("flake_diameter_mm", &flake_diameter_mm);
  r.Num("flake_density_kg_m3", &flake_density_kg_m3);
  r.Vec("wind_m_s", &wind_m_s);
  r.Num("turbulence_m_s", &turbulence_m_s);
  r.Num("drift_frequency_hz", &drift_frequency_hz);
  r.Vec("box_half_extents_m", &box_half_extents_m);
  r.Int("max_particles", &max_particles);
  r.Vec("color", &color);
  r.Bool("sheltered", &sheltered);
}

void SnowParams::Validate(const EffectConfig&, EffectChecker* c) const {
  using R = EffectRange;
  c->In("rate_mm_h", rate_mm_h, R::OpenClosed(0, 100));
  c->In("flake_diameter_mm", flake_diameter_mm, R::Closed(0.5, 30));
  c->In("flake_density_kg_m3", flake_density_kg_m3, R::Closed(20, 900));
  c->In3("wind_m_s", wind_m_s, R::Closed(-100, 100));
  c->In("turbulence_m_s", turbulence_m_s, R::Closed(0, 20));
  c->In("drift_frequency_hz", drift_frequency_hz, R::OpenClosed(0, 100));
  c->In3("box_half_extents_m", box_half_extents_m, R::OpenClosed(0, 1e3));
  c->In("max_particles", max_particles, R::Closed(1, 5e6));
  c->In3("color", color, R::Closed(0, 1));
}

std::unique_ptr<EffectInstance> SnowParams::Bind(const EffectConfig& e,
                                                 const EffectBindContext& ctx) const {
  const uint64_t key = ctx.key;
  return std::make_unique<PrecipitationInstance>(
      [this, key] { return BuildSnowTable(*this, key, 2); }, e.region ? &*e.region : nullptr);
}

}  // namespace penumbra
