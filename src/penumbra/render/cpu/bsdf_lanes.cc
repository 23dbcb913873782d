#include "penumbra/render/cpu/bsdf_lanes.h"

namespace penumbra {
namespace {
constexpr float kPi = 3.14159265358979323846f;
}  // namespace

void BsdfLanes::SetCoefficients(const PbrLanes& p) {
  const Lanes metallic = p.metallic.max(0.0f).min(1.0f);
  const Vec3Lanes base{p.base_color.x.max(0.0f).min(1.0f), p.base_color.y.max(0.0f).min(1.0f),
                       p.base_color.z.max(0.0f).min(1.0f)};
  const Lanes r = p.roughness.max(0.0f).min(1.0f);
  const Lanes alpha = (r * r).max(kMinAlpha);
  const Lanes f0_dielectric = 0.08f * p.specular.max(0.0f).min(1.0f);
  f0 = {f0_dielectric + (base.x - f0_dielectric) * metallic,
        f0_dielectric + (base.y - f0_dielectric) * metallic,
        f0_dielectric + (base.z - f0_dielectric) * metallic};
  const Lanes dielectric = 1.0f - metallic;
  c_diff = {base.x * dielectric, base.y * dielectric, base.z * dielectric};
  a2 = alpha * alpha;
  n_v = n.Dot(wo);
}

Vec3Lanes BsdfLanes::Eval(const Vec3Lanes& wi) const {
  const Lanes n_l = n.Dot(wi);
  const Lanes ng_l = ng.Dot(wi);
  Vec3Lanes h = wo + wi;
  h = h * (1.0f / h.Dot(h).max(1e-30f).sqrt());
  const Lanes v_h = wo.Dot(h).max(0.0f);
  const Lanes n_h = n.Dot(h);
  // sin^2 of the half vector's angle to n: |h x n|^2.
  const Lanes cx = h.y * n.z - h.z * n.y, cy = h.z * n.x - h.x * n.z, cz = h.x * n.y - h.y * n.x;
  const Lanes k = (cx * cx + cy * cy + cz * cz) + a2 * n_h * n_h;
  const Lanes D = a2 / (kPi * k * k);
  // height-correlated Smith visibility G2 / (4 n.l n.v), as Bsdf.
  const Lanes gv = n_l * (n_v * n_v * (1.0f - a2) + a2).sqrt();
  const Lanes gl = n_v * (n_l * n_l * (1.0f - a2) + a2).sqrt();
  const Lanes DV = D * (0.5f / (gv + gl));
  const Lanes m = (1.0f - v_h).max(0.0f).min(1.0f);
  const Lanes m2 = m * m;
  const Lanes m5 = m2 * m2 * m;
  auto channel = [&](const Lanes& f0c, const Lanes& cdc) -> Lanes {
    const Lanes F = f0c + (1.0f - f0c) * m5;
    // valid where n.l, ng.l and n.v are all > 0.
    return WhereAllPositive(n_l, ng_l, n_v, ((1.0f - F) * cdc * (1.0f / kPi) + F * DV) * n_l);
  };
  return {channel(f0.x, c_diff.x), channel(f0.y, c_diff.y), channel(f0.z, c_diff.z)};
}

}  // namespace penumbra
