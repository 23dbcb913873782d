#pragma once
// the reflection model of every surface: the glTF 2.0 metallic-roughness BRDF
// (Khronos glTF 2.0 specification, appendix B "BRDF Implementation"):
//
//   F0      = mix(0.08 specular, base_color, metallic)     (specular 0.5 -> F0 = 0.04)
//   c_diff  = base_color (1 - metallic)
//   F       = F0 + (1 - F0) (1 - |v.h|)^5                  Schlick 1994
//   f       = (1 - F) c_diff / pi  +  F D(h) G2(v, l) / (4 |n.l| |n.v|)
//
// D: GGX / Trowbridge-Reitz with alpha = roughness^2 (Walter, Marschner, Li, Torrance,
// "Microfacet models for refraction through rough surfaces", EGSR 2007); G2: Smith
// height-correlated masking-shadowing (Heitz, "Understanding the masking-shadowing
// function in microfacet-based BRDFs", JCGT 2014). Sampling picks the diffuse lobe
// (cosine-weighted hemisphere) or the specular lobe (GGX visible normals, Heitz,
// "Sampling the GGX distribution of visible normals", JCGT 2018) with a probability from
// the Fresnel reflectance at normal viewing, and Pdf() is the matching one-sample mixture
// density, so Sample/Eval/Pdf are consistent for multiple importance sampling.
//
// all directions are unit vectors in the world frame pointing away from the surface
// (wo towards the viewer, wi towards the light). reflection only: f = 0 unless both wo
// and wi are above the shading and geometric surfaces. the arithmetic is written once, as the
// PB_HOST_DEVICE functions of render/light/bsdf_math.h that the CUDA backend's path kernels call
// too.

#include <Eigen/Core>

#include "penumbra/render/light/brdf_math.h"
#include "penumbra/render/light/bsdf_math.h"

namespace penumbra {

/// parameters of the metallic-roughness BRDF at one surface point.
struct PbrParams {
  Eigen::Vector3f base_color{0.8f, 0.8f, 0.8f};  ///< linear albedo in [0, 1]
  float roughness =
      0.5f;  ///< perceptual roughness in [0, 1]; alpha = roughness^2 (clamped >= kMinAlpha)
  float metallic = 0.0f;  ///< [0, 1]
  float specular = 0.5f;  ///< dielectric specular scale, F0 = 0.08 specular
};

/// result of Bsdf::Sample.
struct BsdfSample {
  Eigen::Vector3f wi{0, 0, 1};     ///< sampled incident direction (unit, world)
  Eigen::Vector3f f_cos{0, 0, 0};  ///< f(wo, wi) |ns . wi|
  float pdf = 0;                   ///< solid-angle density of wi (mixture of both lobes)
};

/// the coefficients of the BRDF formula above, derived from PbrParams (clamped to range).
struct BrdfCoefficients {
  Eigen::Vector3f c_diff{0, 0, 0};  ///< base_color (1 - metallic)
  Eigen::Vector3f f0{0, 0, 0};      ///< mix(0.08 specular, base_color, metallic)
  float alpha = 0.25f;              ///< max(roughness^2, kMinAlpha)

  static BrdfCoefficients From(const PbrParams& params);
};

/// the shading normal used for a view direction: ns_W, or ng_W where wo_W is not above ns_W
/// (a shading normal that faces away from the viewer would make the surface black).
inline Eigen::Vector3f UsableShadingNormal(const Eigen::Vector3f& ns_W, const Eigen::Vector3f& ng_W,
                                           const Eigen::Vector3f& wo_W) {
  return ns_W.dot(wo_W) > 0 ? ns_W : ng_W;
}

/// the BRDF of one shading point, with its shading frame.
class Bsdf {
 public:
  /// @param params  material at the point
  /// @param ns_W    unit shading normal (world); replaced by ng_W where wo is below it
  /// @param ng_W    unit geometric normal (world) on the side of wo
  /// @param wo_W    unit direction towards the viewer (world)
  Bsdf(const PbrParams& params, const Eigen::Vector3f& ns_W, const Eigen::Vector3f& ng_W,
       const Eigen::Vector3f& wo_W);

  /// f(wo, wi) |ns . wi| (1/sr times cosine), rgb. zero for wi below the surface.
  Eigen::Vector3f Eval(const Eigen::Vector3f& wi_W) const;

  /// only the diffuse part of Eval (for split diffuse / specular estimates).
  Eigen::Vector3f EvalDiffuse(const Eigen::Vector3f& wi_W) const;

  /// samples wi from three uniform numbers in [0, 1): u_lobe picks the lobe, (u1, u2) the
  /// direction. returns false (and no sample) when the sampled direction is below the surface.
  bool Sample(float u_lobe, float u1, float u2, BsdfSample* s) const;

  /// solid-angle density with which Sample() returns wi_W.
  float Pdf(const Eigen::Vector3f& wi_W) const;

  /// diffuse albedo c_diff = base_color (1 - metallic) and normal-incidence reflectance F0.
  const Eigen::Vector3f& diffuse_color() const { return c_diff_; }
  const Eigen::Vector3f& f0() const { return f0_; }
  /// the shading normal actually used (world).
  const Eigen::Vector3f& shading_normal() const { return n_; }
  /// GGX alpha = max(roughness^2, kMinAlpha).
  float alpha() const { return pod_.alpha; }
  /// probability with which Sample() picks the specular lobe.
  float specular_probability() const { return pod_.p_spec; }
  /// this BSDF as plain data (render/light/bsdf_math.h, whose functions Eval, Pdf and Sample call).
  const BsdfPod& pod() const { return pod_; }

 private:
  BsdfPod pod_;
  Eigen::Vector3f c_diff_, f0_, n_;
};

}  // namespace penumbra
