#pragma once
// the realtime tier's BRDF arithmetic, shared by the CPU lanes (render/cpu/bsdf_lanes.h) and the
// CUDA kernels (render/transport/surface.h, run by render/cuda/realtime_*.cu): the glTF 2.0
// metallic-roughness BRDF of bsdf.h evaluated in the world frame, and the split-sum ambient
// specular fit. templates over the scalar type T (float or Lanes) and a 3-vector type V with
// members x, y, z of type T (render/shading_math.h).

#include "penumbra/core/host_device.h"
#include "penumbra/render/shading_math.h"

namespace penumbra {

/// smallest GGX alpha used (roughness 0 becomes a very sharp lobe instead of a delta).
constexpr float kMinAlpha = 1e-3f;

/// the coefficients of the BRDF (bsdf.h) from unclamped material parameters, clamped to their
/// ranges: c_diff = base (1 - metallic), f0 = mix(0.08 specular, base, metallic) and
/// a2 = alpha^2, alpha = max(roughness^2, kMinAlpha).
template <typename T, typename V>
PB_HOST_DEVICE inline void BrdfCoefficientsOf(const V& base_color, const T& roughness,
                                              const T& metallic_in, const T& specular, V* c_diff,
                                              V* f0, T* alpha) {
  const T metallic = pbm::Clamp(metallic_in, 0.0f, 1.0f);
  const V base{pbm::Clamp(base_color.x, 0.0f, 1.0f), pbm::Clamp(base_color.y, 0.0f, 1.0f),
               pbm::Clamp(base_color.z, 0.0f, 1.0f)};
  const T r = pbm::Clamp(roughness, 0.0f, 1.0f);
  *alpha = pbm::Max(r * r, kMinAlpha);
  const T f0_dielectric = 0.08f * pbm::Clamp(specular, 0.0f, 1.0f);
  *f0 = V{f0_dielectric + (base.x - f0_dielectric) * metallic,
          f0_dielectric + (base.y - f0_dielectric) * metallic,
          f0_dielectric + (base.z - f0_dielectric) * metallic};
  const T dielectric = 1.0f - metallic;
  *c_diff = V{base.x * dielectric, base.y * dielectric, base.z * dielectric};
}

/// f(wo, wi) |n . wi| (rgb) of the BRDF with coefficients c_diff, f0 and a2 = alpha^2 at a
/// point of unit shading normal n, unit geometric normal ng (viewer's side) and unit view
/// direction wo (n_v = n . wo), for a unit direction wi; 0 where wi or wo is below the shading
/// or geometric surface. D: GGX with sin^2 of the half vector's angle from |h x n|^2, V:
/// height-correlated Smith in Filament's division-free form, F: Schlick (bsdf.h's references).
template <typename T, typename V>
PB_HOST_DEVICE inline V BrdfEvalWorld(const V& n, const V& ng, const V& wo, const T& n_v,
                                      const V& c_diff, const V& f0, const T& a2, const V& wi) {
  constexpr float kPi = pbm::kPi;
  const T n_l = pbm::Dot<T>(n, wi);
  const T ng_l = pbm::Dot<T>(ng, wi);
  V h{wo.x + wi.x, wo.y + wi.y, wo.z + wi.z};
  const T inv_h = 1.0f / pbm::Sqrt(pbm::Max(pbm::Dot<T>(h, h), 1e-30f));
  h = V{h.x * inv_h, h.y * inv_h, h.z * inv_h};
  const T v_h = pbm::Max(pbm::Dot<T>(wo, h), 0.0f);
  const T n_h = pbm::Dot<T>(n, h);
  // sin^2 of the half vector's angle to n: |h x n|^2.
  const T cx = h.y * n.z - h.z * n.y, cy = h.z * n.x - h.x * n.z, cz = h.x * n.y - h.y * n.x;
  const T k = (cx * cx + cy * cy + cz * cz) + a2 * n_h * n_h;
  const T D = a2 / (kPi * k * k);
  // height-correlated Smith visibility G2 / (4 n.l n.v).
  const T gv = n_l * pbm::Sqrt(n_v * n_v * (1.0f - a2) + a2);
  const T gl = n_v * pbm::Sqrt(n_l * n_l * (1.0f - a2) + a2);
  const T DV = D * (0.5f / (gv + gl));
  const T m = pbm::Clamp(1.0f - v_h, 0.0f, 1.0f);
  const T m2 = m * m;
  const T m5 = m2 * m2 * m;
  const T F_r = f0.x + (1.0f - f0.x) * m5;
  const T F_g = f0.y + (1.0f - f0.y) * m5;
  const T F_b = f0.z + (1.0f - f0.z) * m5;
  // valid where n.l, ng.l and n.v are all > 0.
  return V{pbm::WhereAllPositive(n_l, ng_l, n_v,
                                 ((1.0f - F_r) * c_diff.x * (1.0f / kPi) + F_r * DV) * n_l),
           pbm::WhereAllPositive(n_l, ng_l, n_v,
                                 ((1.0f - F_g) * c_diff.y * (1.0f / kPi) + F_g * DV) * n_l),
           pbm::WhereAllPositive(n_l, ng_l, n_v,
                                 ((1.0f - F_b) * c_diff.z * (1.0f / kPi) + F_b * DV) * n_l)};
}

/// split-sum specular reflectance of the ambient term, analytic fit (Karis 2014, "Physically
/// based shading on mobile", Unreal Engine blog) for normal-incidence reflectance f0, n . v
/// (>= 0) and perceptual roughness in [0, 1]; each channel in [0, 1]. exp2(-9.28 n.v) is
/// taken as exp(-9.28 ln2 n.v) (pbm::Exp: Eigen's vectorised exp on lanes, expf on floats).
template <typename T, typename V>
PB_HOST_DEVICE inline V EnvBrdfApprox(const V& f0, const T& n_v, const T& roughness) {
  constexpr float kLn2 = 0.693147180559945309f;
  const T r0 = roughness * -1.0f + 1.0f;
  const T r1 = roughness * -0.0275f + 0.0425f;
  const T r2 = roughness * -0.572f + 1.04f;
  const T r3 = roughness * 0.022f - 0.04f;
  const T e = pbm::Exp(n_v * (-9.28f * kLn2));
  const T a004 = pbm::Min(r0 * r0, e) * r0 + r1;
  const T a = a004 * -1.04f + r2;
  const T b = a004 * 1.04f + r3;
  return V{pbm::Clamp(f0.x * a + b, 0.0f, 1.0f), pbm::Clamp(f0.y * a + b, 0.0f, 1.0f),
           pbm::Clamp(f0.z * a + b, 0.0f, 1.0f)};
}

}  // namespace penumbra
