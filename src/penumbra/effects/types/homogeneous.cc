#include "penumbra/effects/types/homogeneous.h"

#include <cmath>

namespace penumbra {

double ExtinctionSpec::SigmaT() const {
  if (sigma_t_per_m) return *sigma_t_per_m;
  if (mor_m) return -std::log(0.05) / *mor_m;
  return 0;
}

void ReadExtinction(const EffectParamReader& r, ExtinctionSpec* e) {
  if (r.Has("sigma_t_per_m")) e->sigma_t_per_m = r.Double("sigma_t_per_m");
  if (r.Has("mor_m")) e->mor_m = r.Double("mor_m");
}

void CheckExtinction(const ExtinctionSpec& e, EffectChecker* c) {
  if (e.sigma_t_per_m && e.mor_m) {
    c->Fail("mor_m", "both sigma_t_per_m and mor_m are set; expected exactly one");
  } else if (!e.sigma_t_per_m && !e.mor_m) {
    c->Fail("mor_m",
            "neither sigma_t_per_m nor mor_m is set; expected exactly one (extinction 1/m or "
            "meteorological optical range m)");
  } else if (e.sigma_t_per_m) {
    c->In("sigma_t_per_m", *e.sigma_t_per_m, EffectRange::OpenClosed(0, 1e3));
  } else {
    c->In("mor_m", *e.mor_m, EffectRange::AtLeast(1e-3));
  }
}

HomogeneousMedium MakeHomogeneousMedium(double sigma_t_per_m, const Eigen::Vector3d& albedo,
                                        double g, double height_falloff_per_m, double base_height_m,
                                        const std::optional<BoxRegion>& region, double w) {
  HomogeneousMedium m;
  m.sigma_t_per_m = Eigen::Vector3f::Constant(static_cast<float>(sigma_t_per_m * w));
  m.albedo = albedo.cast<float>();
  m.g = static_cast<float>(g);
  m.height_falloff_per_m = static_cast<float>(height_falloff_per_m);
  m.base_height_m = static_cast<float>(base_height_m);
  m.region = region;
  return m;
}

}  // namespace penumbra
