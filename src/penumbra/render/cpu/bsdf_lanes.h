#pragma once
// the BRDF of bsdf.h (glTF 2.0 metallic-roughness: Lambert + GGX, Smith height-correlated,
// Schlick) evaluated for kLanes shading points at once, in the world frame. used by the
// realtime tier; agrees with Bsdf::Eval to float rounding (same formulas; sin^2 of the half
// vector from |h x n|^2 as Bsdf takes it from the local frame).

#include "penumbra/render/light/bsdf.h"
#include "penumbra/render/shading_lanes.h"

namespace penumbra {

/// the metallic-roughness parameters (PbrParams) of kLanes points, unclamped.
struct PbrLanes {
  Vec3Lanes base_color;                 ///< linear albedo (x = r, y = g, z = b)
  Lanes roughness, metallic, specular;  ///< as PbrParams

  /// sets lane k to `p`.
  void Set(int k, const PbrParams& p) {
    base_color.Set(k, p.base_color);
    roughness[k] = p.roughness;
    metallic[k] = p.metallic;
    specular[k] = p.specular;
  }
};

/// kLanes shading points: frame, view direction and BRDF parameters per lane.
struct BsdfLanes {
  Vec3Lanes n;           ///< unit shading normal actually used (Bsdf::shading_normal())
  Vec3Lanes ng;          ///< unit geometric normal on the viewer's side
  Vec3Lanes wo;          ///< unit direction towards the viewer
  Lanes n_v;             ///< n . wo
  Vec3Lanes c_diff, f0;  ///< Bsdf::diffuse_color(), Bsdf::f0() (x = r, y = g, z = b)
  Lanes a2;              ///< Bsdf::alpha()^2

  /// sets the frame of lane k: n = n_s (the usable shading normal, UsableShadingNormal(ns_W,
  /// ng_W, wo_W)), ng = ng_W, wo = wo_W. n_v and the coefficients follow from SetCoefficients.
  void SetFrame(int k, const Eigen::Vector3f& n_s, const Eigen::Vector3f& ng_W,
                const Eigen::Vector3f& wo_W) {
    n.Set(k, n_s);
    ng.Set(k, ng_W);
    wo.Set(k, wo_W);
  }

  /// for every lane: c_diff, f0 and a2 from `p` (the arithmetic of BrdfCoefficients::From,
  /// so a lane's BRDF is the one Bsdf(params, ns_W, ng_W, wo_W) has) and n_v = n . wo from the
  /// frame set by SetFrame.
  void SetCoefficients(const PbrLanes& p);

  /// f(wo, wi) |n . wi| per lane (x = r, y = g, z = b) for unit directions wi; 0 where wi or
  /// wo is below the shading or geometric surface (as Bsdf::Eval).
  Vec3Lanes Eval(const Vec3Lanes& wi) const;
};

}  // namespace penumbra
