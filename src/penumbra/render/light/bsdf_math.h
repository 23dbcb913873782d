#pragma once
// the scalar BSDF of the pathtraced tier (render/light/bsdf.h: the glTF 2.0 metallic-roughness BRDF
// in a local shading frame, with its lobe choice, visible-normal sampling and one-sample mixture
// density) as PB_HOST_DEVICE functions over plain data: the CPU's Bsdf class and the CUDA
// backend's path kernels (render/transport/path_trace.h) call these, so the formulas exist once.
// the references and the model are documented in bsdf.h.
//
// bit-for-bit rule (render/shading_math.h): every expression keeps the operation order of the
// Eigen code it replaced: a dot product sums x + (y + z) as Eigen's fixed-size reduction does
// (EigenDot; pbm::Dot sums (x + y) + z), a normalisation divides each component by the norm, as
// Eigen's normalized() does (not a multiplication by its inverse), and the frame's basis takes
// the sign of n.z by copysign (so -0 counts as negative, as std::copysign).

#include <cmath>

#include "penumbra/core/host_device.h"
#include "penumbra/render/light/brdf_math.h"
#include "penumbra/render/shading_math.h"

namespace penumbra {

namespace bsdf_detail {

/// 1 / pi as the Bsdf has always computed it (1.0f / kPi in float).
constexpr float kInvPi = 1.0f / pbm::kPi;

/// a . b as Eigen sums a fixed-size 3-vector's dot product (and squaredNorm): x + (y + z), its
/// reduction splitting the three terms in halves (Eigen 3.4, Redux.h's redux_novec_unroller).
PB_HOST_DEVICE inline float Dot3(const Float3& a, const Float3& b) {
  return a.x * b.x + (a.y * b.y + a.z * b.z);
}
/// v / |v| component by component where |v|^2 > 0, else v (Eigen's normalized()).
PB_HOST_DEVICE inline Float3 Normalized(const Float3& v) {
  const float z = Dot3(v, v);
  if (!(z > 0.0f)) return v;
  const float n = sqrtf(z);
  return Float3{v.x / n, v.y / n, v.z / n};
}
/// copysign(1, x).
PB_HOST_DEVICE inline float CopySignOne(float x) { return copysignf(1.0f, x); }

}  // namespace bsdf_detail

/// a . b summed as Eigen sums a 3-vector's dot product and squared norm: x + (y + z) (the scalar
/// formulas that replaced Eigen code use it to keep its bits; bsdf_detail::Dot3).
PB_HOST_DEVICE inline float EigenDot(const Float3& a, const Float3& b) {
  return bsdf_detail::Dot3(a, b);
}

/// Rec. 709 luminance of an rgb value, as the Bsdf's lobe choice takes it.
PB_HOST_DEVICE inline float BsdfLuminance(const Float3& c) {
  return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z;
}

/// Schlick's Fresnel approximation for reflectance f0 at cos_theta = v.h (Schlick 1994).
PB_HOST_DEVICE inline Float3 BsdfSchlick(const Float3& f0, float cos_theta) {
  const float m = pbm::Clamp(1.0f - cos_theta, 0.0f, 1.0f);
  const float m2 = m * m;
  const float m5 = m2 * m2 * m;
  return Float3{f0.x + (1.0f - f0.x) * m5, f0.y + (1.0f - f0.y) * m5, f0.z + (1.0f - f0.z) * m5};
}

/// GGX normal distribution D(h) of a unit half vector h in the shading frame, a2 = alpha^2
/// (Walter et al. 2007, eq. 33, as a2 / (pi (sin^2 + a2 cos^2)^2), sin^2 = h.x^2 + h.y^2).
PB_HOST_DEVICE inline float BsdfGgxD(const Float3& h, float a2) {
  const float k = (h.x * h.x + h.y * h.y) + a2 * h.z * h.z;
  return a2 / (pbm::kPi * k * k);
}

/// Smith Lambda for GGX (Heitz 2014, eq. 72) of a unit direction w in the shading frame.
PB_HOST_DEVICE inline float BsdfGgxLambda(const Float3& w, float a2) {
  const float tan2 = (w.x * w.x + w.y * w.y) / (w.z * w.z);
  return 0.5f * (-1.0f + sqrtf(1.0f + a2 * tan2));
}

/// V = G2 / (4 n.l n.v), height-correlated Smith (Heitz 2014, eq. 99) in Filament's form.
PB_HOST_DEVICE inline float BsdfSmithVisibility(float n_v, float n_l, float a2) {
  const float gv = n_l * sqrtf(n_v * n_v * (1.0f - a2) + a2);
  const float gl = n_v * sqrtf(n_l * n_l * (1.0f - a2) + a2);
  return 0.5f / (gv + gl);
}

/// the BSDF of one shading point (bsdf.h's Bsdf as plain data): coefficients, local frame
/// t, b, n (n the usable shading normal), the geometric normal ng and wo in the local frame.
struct BsdfPod {
  Float3 c_diff, f0;
  Float3 t, b, n, ng;
  Float3 wo;  ///< local frame
  float alpha = 0.25f;
  float p_spec = 0.5f;
};

/// v in the local frame of s: (v . t, v . b, v . n).
PB_HOST_DEVICE inline Float3 BsdfToLocal(const BsdfPod& s, const Float3& v) {
  return Float3{bsdf_detail::Dot3(v, s.t), bsdf_detail::Dot3(v, s.b), bsdf_detail::Dot3(v, s.n)};
}
/// local v back in the world: v.x t + v.y b + v.z n.
PB_HOST_DEVICE inline Float3 BsdfFromLocal(const BsdfPod& s, const Float3& v) {
  return Float3{v.x * s.t.x + v.y * s.b.x + v.z * s.n.x, v.x * s.t.y + v.y * s.b.y + v.z * s.n.y,
                v.x * s.t.z + v.y * s.b.z + v.z * s.n.z};
}

/// the BSDF at a point: material coefficients c_diff, f0 and alpha (BrdfCoefficientsOf), unit
/// shading normal ns_W (replaced by ng_W where wo_W is not above it), unit geometric normal
/// ng_W on the side of wo_W, unit direction wo_W towards the viewer (all world frame). the
/// frame's basis: Duff et al., "Building an orthonormal basis, revisited", JCGT 2017.
PB_HOST_DEVICE inline BsdfPod MakeBsdf(const Float3& c_diff, const Float3& f0, float alpha,
                                       const Float3& ns_W, const Float3& ng_W, const Float3& wo_W) {
  BsdfPod s;
  s.ng = ng_W;
  s.alpha = alpha;
  s.f0 = f0;
  s.c_diff = c_diff;
  s.n = bsdf_detail::Dot3(ns_W, wo_W) > 0 ? ns_W : ng_W;
  const Float3& n = s.n;
  const float sign = bsdf_detail::CopySignOne(n.z);
  const float a = -1.0f / (sign + n.z);
  const float c = n.x * n.y * a;
  s.t = Float3{1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x};
  s.b = Float3{c, sign + n.y * n.y * a, -n.y};
  s.wo = BsdfToLocal(s, wo_W);
  // lobe selection from the Fresnel reflectance at the viewing angle.
  const float cos_o = pbm::Max(s.wo.z, 0.0f);
  const Float3 F = BsdfSchlick(s.f0, cos_o);
  const float ws = BsdfLuminance(F);
  const float wd = BsdfLuminance(
      Float3{s.c_diff.x * (1.0f - F.x), s.c_diff.y * (1.0f - F.y), s.c_diff.z * (1.0f - F.z)});
  if (wd <= 0) {
    s.p_spec = 1.0f;
  } else {
    s.p_spec = pbm::Clamp(ws / (ws + wd), 0.1f, 0.9f);
  }
  return s;
}

/// f(wo, wi) |n . wi| for a local direction wi, the specular lobe with with_specular.
PB_HOST_DEVICE inline Float3 BsdfEvalLocal(const BsdfPod& s, const Float3& wi, bool with_specular) {
  const float n_v = s.wo.z, n_l = wi.z;
  if (n_v <= 0 || n_l <= 0) return Float3{};
  Float3 h{s.wo.x + wi.x, s.wo.y + wi.y, s.wo.z + wi.z};
  const float hl = sqrtf(bsdf_detail::Dot3(h, h));
  if (!(hl > 0)) return Float3{};
  h = Float3{h.x / hl, h.y / hl, h.z / hl};
  const float v_h = pbm::Max(bsdf_detail::Dot3(s.wo, h), 0.0f);
  const Float3 F = BsdfSchlick(s.f0, v_h);
  Float3 f{(1.0f - F.x) * s.c_diff.x * bsdf_detail::kInvPi,
           (1.0f - F.y) * s.c_diff.y * bsdf_detail::kInvPi,
           (1.0f - F.z) * s.c_diff.z * bsdf_detail::kInvPi};
  if (with_specular) {
    const float a2 = s.alpha * s.alpha;
    const float dv = BsdfGgxD(h, a2) * BsdfSmithVisibility(n_v, n_l, a2);
    f = Float3{f.x + F.x * dv, f.y + F.y * dv, f.z + F.z * dv};
  }
  return Float3{f.x * n_l, f.y * n_l, f.z * n_l};
}

/// the solid-angle density of a local direction wi (the one-sample mixture of both lobes).
PB_HOST_DEVICE inline float BsdfPdfLocal(const BsdfPod& s, const Float3& wi) {
  if (s.wo.z <= 0 || wi.z <= 0) return 0.0f;
  float pdf = (1.0f - s.p_spec) * wi.z * bsdf_detail::kInvPi;
  if (s.p_spec > 0) {
    Float3 h{s.wo.x + wi.x, s.wo.y + wi.y, s.wo.z + wi.z};
    const float hl = sqrtf(bsdf_detail::Dot3(h, h));
    if (hl > 0) {
      h = Float3{h.x / hl, h.y / hl, h.z / hl};
      const float a2 = s.alpha * s.alpha;
      // visible-normal density reflected about h: D(h) G1(wo) / (4 wo.z) (Heitz 2018, eq. 17
      // and 1 / (4 wo.h)).
      const float g1 = 1.0f / (1.0f + BsdfGgxLambda(s.wo, a2));
      pdf += s.p_spec * BsdfGgxD(h, a2) * g1 / (4.0f * s.wo.z);
    }
  }
  return pdf;
}

/// Bsdf::Eval: f(wo, wi) |ns . wi| for a unit world direction wi_W; 0 below the surface.
PB_HOST_DEVICE inline Float3 BsdfEval(const BsdfPod& s, const Float3& wi_W) {
  if (bsdf_detail::Dot3(wi_W, s.ng) <= 0) return Float3{};
  return BsdfEvalLocal(s, BsdfToLocal(s, wi_W), true);
}

/// Bsdf::EvalDiffuse: the diffuse part of BsdfEval.
PB_HOST_DEVICE inline Float3 BsdfEvalDiffuse(const BsdfPod& s, const Float3& wi_W) {
  if (bsdf_detail::Dot3(wi_W, s.ng) <= 0) return Float3{};
  return BsdfEvalLocal(s, BsdfToLocal(s, wi_W), false);
}

/// Bsdf::Pdf: the solid-angle density with which SampleBsdf returns wi_W.
PB_HOST_DEVICE inline float BsdfPdf(const BsdfPod& s, const Float3& wi_W) {
  if (bsdf_detail::Dot3(wi_W, s.ng) <= 0) return 0.0f;
  return BsdfPdfLocal(s, BsdfToLocal(s, wi_W));
}

/// Bsdf::Sample: a direction from three uniform numbers in [0, 1) (u_lobe picks the lobe, u1
/// and u2 the direction: GGX visible normals, Heitz 2018 listing 1, or Malley's cosine
/// hemisphere), its value *f_cos = BsdfEval and density *pdf = BsdfPdf of the returned unit
/// world direction *wi. false (outputs unspecified) when the direction is below the surface or
/// has zero density.
PB_HOST_DEVICE inline bool SampleBsdf(const BsdfPod& s, float u_lobe, float u1, float u2,
                                      Float3* wi_out, Float3* f_cos, float* pdf) {
  const Float3& wo = s.wo;
  if (wo.z <= 0) return false;
  Float3 wi;
  if (u_lobe < s.p_spec) {
    // stretch wo, sample the projected hemisphere, unstretch the normal, reflect wo about it.
    const Float3 vh = bsdf_detail::Normalized(Float3{s.alpha * wo.x, s.alpha * wo.y, wo.z});
    const float lensq = vh.x * vh.x + vh.y * vh.y;
    Float3 t1{1, 0, 0};
    if (lensq > 0) {
      const float l = sqrtf(lensq);
      t1 = Float3{-vh.y / l, vh.x / l, 0.0f / l};
    }
    const Float3 t2{vh.y * t1.z - vh.z * t1.y, vh.z * t1.x - vh.x * t1.z,
                    vh.x * t1.y - vh.y * t1.x};
    const float r = sqrtf(u1);
    const float phi = 2.0f * pbm::kPi * u2;
    const float p1 = r * cosf(phi);
    float p2 = r * sinf(phi);
    const float sh = 0.5f * (1.0f + vh.z);
    p2 = (1.0f - sh) * sqrtf(pbm::Max(0.0f, 1.0f - p1 * p1)) + sh * p2;
    const float pz = sqrtf(pbm::Max(0.0f, 1.0f - p1 * p1 - p2 * p2));
    const Float3 nh{p1 * t1.x + p2 * t2.x + pz * vh.x, p1 * t1.y + p2 * t2.y + pz * vh.y,
                    p1 * t1.z + p2 * t2.z + pz * vh.z};
    const Float3 m =
        bsdf_detail::Normalized(Float3{s.alpha * nh.x, s.alpha * nh.y, pbm::Max(0.0f, nh.z)});
    const float k = 2.0f * bsdf_detail::Dot3(wo, m);
    wi = Float3{k * m.x - wo.x, k * m.y - wo.y, k * m.z - wo.z};
  } else {
    const float r = sqrtf(u1);
    const float phi = 2.0f * pbm::kPi * u2;
    wi = Float3{r * cosf(phi), r * sinf(phi), sqrtf(pbm::Max(0.0f, 1.0f - u1))};
  }
  if (wi.z <= 0) return false;
  // value and density of the returned (world, unit) direction itself, so that the sample
  // agrees with BsdfEval and BsdfPdf to the last bit.
  const Float3 wi_W = bsdf_detail::Normalized(BsdfFromLocal(s, wi));
  if (bsdf_detail::Dot3(wi_W, s.ng) <= 0) return false;
  *wi_out = wi_W;
  *f_cos = BsdfEval(s, wi_W);
  *pdf = BsdfPdf(s, wi_W);
  return *pdf > 0;
}

}  // namespace penumbra
