#include "penumbra/render/light/bsdf.h"

namespace penumbra {
namespace {

Float3 F3(const Eigen::Vector3f& v) { return Float3{v.x(), v.y(), v.z()}; }
Eigen::Vector3f E3(const Float3& v) { return Eigen::Vector3f(v.x, v.y, v.z); }

}  // namespace

BrdfCoefficients BrdfCoefficients::From(const PbrParams& params) {
  // the shared formula (render/light/brdf_math.h), as the realtime tier's lanes and the GPU take
  // it.
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
           const Eigen::Vector3f& wo_W) {
  const BrdfCoefficients c = BrdfCoefficients::From(params);
  f0_ = c.f0;
  c_diff_ = c.c_diff;
  pod_ = MakeBsdf(F3(c.c_diff), F3(c.f0), c.alpha, F3(ns_W), F3(ng_W), F3(wo_W));
  n_ = E3(pod_.n);
}

Eigen::Vector3f Bsdf::Eval(const Eigen::Vector3f& wi_W) const {
  return E3(BsdfEval(pod_, F3(wi_W)));
}

Eigen::Vector3f Bsdf::EvalDiffuse(const Eigen::Vector3f& wi_W) const {
  return E3(BsdfEvalDiffuse(pod_, F3(wi_W)));
}

float Bsdf::Pdf(const Eigen::Vector3f& wi_W) const { return BsdfPdf(pod_, F3(wi_W)); }

bool Bsdf::Sample(float u_lobe, float u1, float u2, BsdfSample* s) const {
  Float3 wi, f_cos;
  float pdf = 0;
  if (!SampleBsdf(pod_, u_lobe, u1, u2, &wi, &f_cos, &pdf)) return false;
  s->wi = E3(wi);
  s->f_cos = E3(f_cos);
  s->pdf = pdf;
  return true;
}

}  // namespace penumbra
