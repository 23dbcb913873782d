#include "penumbra/render/cpu/bsdf_lanes.h"

#include "penumbra/render/light/brdf_math.h"

namespace penumbra {
void BsdfLanes::SetCoefficients(const PbrLanes& p) {
  Lanes alpha;
  BrdfCoefficientsOf<Lanes, Vec3Lanes>(p.base_color, p.roughness, p.metallic, p.specular, &c_diff,
                                       &f0, &alpha);
  a2 = alpha * alpha;
  n_v = n.Dot(wo);
}

Vec3Lanes BsdfLanes::Eval(const Vec3Lanes& wi) const {
  return BrdfEvalWorld<Lanes, Vec3Lanes>(n, ng, wo, n_v, c_diff, f0, a2, wi);
}

}  // namespace penumbra
