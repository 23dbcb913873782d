#include "penumbra/effects/types/fluid_params.h"

#include <string>

#include "penumbra/scene/scene_limits.h"

namespace penumbra {

std::vector<std::string_view> FluidParams::Keys() {
  return {"resolution",        "dt_sec",
          "jacobi_iterations", "buoyancy_m_s2",
          "weight_m_s2",       "dissipation_per_s",
          "cooling_per_s",     "ambient_temperature_k",
          "turbulence_m_s",    "emitters"};
}

void FluidParams::Read(const EffectParamReader& r) {
  r.Int("resolution", &resolution);
  r.Num("dt_sec", &dt_sec);
  r.Int("jacobi_iterations", &jacobi_iterations);
  r.Num("buoyancy_m_s2", &buoyancy_m_s2);
  r.Num("weight_m_s2", &weight_m_s2);
  r.Num("dissipation_per_s", &dissipation_per_s);
  r.Num("cooling_per_s", &cooling_per_s);
  r.Num("ambient_temperature_k", &ambient_temperature_k);
  r.Num("turbulence_m_s", &turbulence_m_s);
  if (r.Has("emitters")) {
    emitters.clear();
    for (const auto& e : r.List("emitters")) {
      e->ExpectKeys({"position", "radius_m", "rate", "temperature_k"});
      PlumeEmitter em;
      em.position_W = e->Vector3("position");  // required
      e->Num("radius_m", &em.radius_m);
      e->Num("rate", &em.rate);
      e->Num("temperature_k", &em.temperature_k);
      emitters.push_back(em);
    }
  }
}

void FluidParams::Validate(const std::optional<BoxRegion>& region, EffectChecker* c) const {
  using R = EffectRange;
  c->In("resolution", resolution, R::Closed(8, 128));
  c->In("dt_sec", dt_sec, R::Closed(kMinDtSec, kMaxDtSec));
  c->In("jacobi_iterations", jacobi_iterations, R::Closed(1, 200));
  // accelerations up to 100 g and rates up to 1000 per second: beyond them one step of the
  // grid already overflows the 32-bit floats the renderer reads (1e308 made the grid NaN)
  c->In("buoyancy_m_s2", buoyancy_m_s2, R::Closed(0, kMaxFluidAccelerationM_S2));
  c->In("weight_m_s2", weight_m_s2, R::Closed(0, kMaxFluidAccelerationM_S2));
  c->In("dissipation_per_s", dissipation_per_s, R::Closed(0, kMaxFluidRatePerS));
  c->In("cooling_per_s", cooling_per_s, R::Closed(0, kMaxFluidRatePerS));
  c->In("ambient_temperature_k", ambient_temperature_k, R::Closed(200, 400));
  c->In("turbulence_m_s", turbulence_m_s, R::Closed(0, 20));
  if (emitters.empty()) {
    c->Fail("emitters", "no emitters; expected a list of at least one emitter");
  }
  for (size_t i = 0; i < emitters.size(); ++i) {
    const PlumeEmitter& e = emitters[i];
    const std::string k = "emitters[" + std::to_string(i) + "]";
    c->In3(k + ".position", e.position_W, R::Closed(-kMaxPositionM, kMaxPositionM));
    c->In(k + ".radius_m", e.radius_m, R::OpenClosed(0, kMaxGeomSizeM));
    c->In(k + ".rate", e.rate, R::Closed(0, kMaxFluidRatePerS));
    c->In(k + ".temperature_k", e.temperature_k, R::Closed(300, 4000));
    if (c->ok() && region) {
      const Eigen::Vector3d& p0 = e.position_W;
      if ((p0.array() < region->min_W.array()).any() ||
          (p0.array() > region->max_W.array()).any()) {
        using N = EffectChecker;
        c->Fail(k + ".position",
                "emitter lies outside the effect's region; expected a point in [" +
                    N::Num(region->min_W.x()) + ", " + N::Num(region->max_W.x()) + "] x [" +
                    N::Num(region->min_W.y()) + ", " + N::Num(region->max_W.y()) + "] x [" +
                    N::Num(region->min_W.z()) + ", " + N::Num(region->max_W.z()) + "]");
      }
    }
  }
}

}  // namespace penumbra
