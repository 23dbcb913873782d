#include "penumbra/render/bsdf.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace penumbra {
namespace {

constexpr float kPi = 3.14159265358979323846f;
constexpr float kInvPi = 1.0f / kPi;

// Rec. 709 luminance weights (IEC 61966-2-1).
inline float BsdfLuminance(const Eigen::Vector3f& c) {
  return 0.2126f * c.x() + 0.7152f * c.y() + 0.0722f * c.z();
}

// Schlick's Fresnel approximation for reflectance f0 at cos_theta = v.h.
inline Eigen::Vector3f Schlick(const Eigen::Vector3f& f0, float cos_theta) {
  const float m = std::clamp(1.0f - cos_theta, 0.0f, 1.0f);
  const float m2 = m * m;
  const float m5 = m2 * m2 * m;
  return f0 + (Eigen::Vector3f::Ones() - f0) * m5;
}

// GGX normal distribution D(h) for a unit half vector h in the shading frame (Walter et al.
// 2007, eq. 33, written as a2 / (pi (sin^2 + a2 cos^2)^2) with sin^2 = h.x^2 + h.y^2, which
// keeps its precision for very smooth surfaces, unlike 1 - cos^2).
inline float GgxD(const Eigen::Vector3f& h, float a2) {
  const float k = (h.x() * h.x() + h.y() * h.y()) + a2 * h.z() * h.z();
  return a2 / (kPi * k * k);
}

// Smith Lambda for GGX (Heitz 2014, eq. 72) of a unit direction w in the shading frame.
inline float GgxLambda(const Eigen::Vector3f& w, float a2) {
  const float tan2 = (w.x() * w.x() + w.y() * w.y()) / (w.z() * w.z());
  return 0.5f * (-1.0f + std::sqrt(1.0f + a2 * tan2));
}

// V = G2 / (4 n.l n.v) with the height-correlated Smith G2 (Heitz 2014, eq. 99), in the
// division-free form used by Filament (Guy, Agopian, "Physically based rendering in Filament").
inline float SmithVisibility(float n_v, float n_l, float a2) {
  const float gv = n_l * std::sqrt(n_v * n_v * (1.0f - a2) + a2);
  const float gl = n_v * std::sqrt(n_l * n_l * (1.0f - a2) + a2);
  return 0.5f / (gv + gl);
}

// orthonormal basis around unit n (Duff et al., "Building an orthonormal basis, revisited", JCGT
// 2017).
inline void Basis(const Eigen::Vector3f& n, Eigen::Vector3f* t, Eigen::Vector3f* b) {
  const float sign = std::copysign(1.0f, n.z());
  const float a = -1.0f / (sign + n.z());
  const float c = n.x() * n.y() * a;
  *t = Eigen::Vector3f(1.0f + sign * n.x() * n.x() * a, sign * c, -sign * n.x());
  *b = Eigen::Vector3f(c, sign + n.y() * n.y() * a, -n.y());
}

}  // namespace

BrdfCoefficients BrdfCoefficients::From(const PbrParams& params) {
  // the shared formula (render/brdf_math.h), as the realtime tier's lanes and the GPU take it.
  BrdfCoefficients c;
  Float3 c_diff, f0;
  BrdfCoefficientsOf<float, Float3>(
      Float3{params.base_color.x(), params.base_color.y(), params.base_color.z()}, params.roughness,
      params.metallic, params.specular, &c_diff, &f0, &c.alpha);
  c.c_diff = Eigen::Vector3f(c_diff.x, c_diff.y, c_diff.z);
  c.f0 = Eigen::Vector3f(f0.x, f0.y, f0.z);
  return c;
}

Bsdf::Bsdf(const PbrParams& params, const Eigen::Vector3f& ns_W, const Eigen::Vector3f& ng_W,
           const Eigen::Vector3f& wo_W)
    : ng_(ng_W) {
  const BrdfCoefficients c = BrdfCoefficients::From(params);
  alpha_ = c.alpha;
  f0_ = c.f0;
  c_diff_ = c.c_diff;
  n_ = UsableShadingNormal(ns_W, ng_W, wo_W);
  Basis(n_, &t_, &b_);
  wo_ = ToLocal(wo_W);

  // lobe selection from the Fresnel reflectance at the viewing angle.
  const float cos_o = std::max(wo_.z(), 0.0f);
  const Eigen::Vector3f F = Schlick(f0_, cos_o);
  const float ws = BsdfLuminance(F);
  const float wd = BsdfLuminance(c_diff_.cwiseProduct(Eigen::Vector3f::Ones() - F));
  if (wd <= 0) {
    p_spec_ = 1.0f;
  } else {
    p_spec_ = std::clamp(ws / (ws + wd), 0.1f, 0.9f);
  }
}

Eigen::Vector3f Bsdf::EvalLocal(const Eigen::Vector3f& wi, bool with_specular) const {
  const float n_v = wo_.z(), n_l = wi.z();
  if (n_v <= 0 || n_l <= 0) return Eigen::Vector3f::Zero();
  Eigen::Vector3f h = wo_ + wi;
  const float hl = h.norm();
  if (!(hl > 0)) return Eigen::Vector3f::Zero();
  h /= hl;
  const float v_h = std::max(wo_.dot(h), 0.0f);
  const Eigen::Vector3f F = Schlick(f0_, v_h);
  Eigen::Vector3f f = (Eigen::Vector3f::Ones() - F).cwiseProduct(c_diff_) * kInvPi;
  if (with_specular) {
    const float a2 = alpha_ * alpha_;
    f += F * (GgxD(h, a2) * SmithVisibility(n_v, n_l, a2));
  }
  return f * n_l;
}

float Bsdf::PdfLocal(const Eigen::Vector3f& wi) const {
  if (wo_.z() <= 0 || wi.z() <= 0) return 0.0f;
  float pdf = (1.0f - p_spec_) * wi.z() * kInvPi;
  if (p_spec_ > 0) {
    Eigen::Vector3f h = wo_ + wi;
    const float hl = h.norm();
    if (hl > 0) {
      h /= hl;
      const float a2 = alpha_ * alpha_;
      // visible-normal density reflected about h: D(h) G1(wo) / (4 wo.z) (Heitz 2018, eq. 17 and 1
      // / (4 wo.h)).
      const float g1 = 1.0f / (1.0f + GgxLambda(wo_, a2));
      pdf += p_spec_ * GgxD(h, a2) * g1 / (4.0f * wo_.z());
    }
  }
  return pdf;
}

Eigen::Vector3f Bsdf::Eval(const Eigen::Vector3f& wi_W) const {
  if (wi_W.dot(ng_) <= 0) return Eigen::Vector3f::Zero();
  return EvalLocal(ToLocal(wi_W), true);
}

Eigen::Vector3f Bsdf::EvalDiffuse(const Eigen::Vector3f& wi_W) const {
  if (wi_W.dot(ng_) <= 0) return Eigen::Vector3f::Zero();
  return EvalLocal(ToLocal(wi_W), false);
}

float Bsdf::Pdf(const Eigen::Vector3f& wi_W) const {
  if (wi_W.dot(ng_) <= 0) return 0.0f;
  return PdfLocal(ToLocal(wi_W));
}

bool Bsdf::Sample(float u_lobe, float u1, float u2, BsdfSample* s) const {
  if (wo_.z() <= 0) return false;
  Eigen::Vector3f wi;
  if (u_lobe < p_spec_) {
    // GGX visible normals (Heitz 2018, listing 1): stretch wo, sample the projected
    // hemisphere, unstretch the normal, reflect wo about it.
    const Eigen::Vector3f vh =
        Eigen::Vector3f(alpha_ * wo_.x(), alpha_ * wo_.y(), wo_.z()).normalized();
    const float lensq = vh.x() * vh.x() + vh.y() * vh.y();
    const Eigen::Vector3f t1 = lensq > 0 ? Eigen::Vector3f(-vh.y(), vh.x(), 0) / std::sqrt(lensq)
                                         : Eigen::Vector3f(1, 0, 0);
    const Eigen::Vector3f t2 = vh.cross(t1);
    const float r = std::sqrt(u1);
    const float phi = 2.0f * kPi * u2;
    const float p1 = r * std::cos(phi);
    float p2 = r * std::sin(phi);
    const float sh = 0.5f * (1.0f + vh.z());
    p2 = (1.0f - sh) * std::sqrt(std::max(0.0f, 1.0f - p1 * p1)) + sh * p2;
    const Eigen::Vector3f nh =
        p1 * t1 + p2 * t2 + std::sqrt(std::max(0.0f, 1.0f - p1 * p1 - p2 * p2)) * vh;
    const Eigen::Vector3f m =
        Eigen::Vector3f(alpha_ * nh.x(), alpha_ * nh.y(), std::max(0.0f, nh.z())).normalized();
    wi = 2.0f * wo_.dot(m) * m - wo_;
  } else {
    // cosine-weighted hemisphere (Malley's method).
    const float r = std::sqrt(u1);
    const float phi = 2.0f * kPi * u2;
    wi =
        Eigen::Vector3f(r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0f, 1.0f - u1)));
  }
  if (wi.z() <= 0) return false;
  // value and density of the returned (world, unit) direction itself, so that Sample agrees
  // with Eval and Pdf to the last bit.
  const Eigen::Vector3f wi_W = FromLocal(wi).normalized();
  if (wi_W.dot(ng_) <= 0) return false;
  s->wi = wi_W;
  s->f_cos = Eval(wi_W);
  s->pdf = Pdf(wi_W);
  return s->pdf > 0;
}

}  // namespace penumbra
