#pragma once
// one sample of an analytic light (render/light/light_sampler.h: directional, point and spot
// lights, spheres and sun discs sampled for soft shadows) as seen from a shading point, shared by
// the CPU's lanes (LightSampler::SampleLanes) and the CUDA kernels. templates over the scalar type
// T (float or Lanes) and its 3-vector V (render/shading_math.h); the light itself is the POD
// LightPod, which LightSampler keeps beside its posed lights and the CUDA backend uploads.

#include <cmath>

#include "penumbra/core/host_device.h"
#include "penumbra/render/shading_math.h"

namespace penumbra {

/// the kind of a LightPod (Light::Type's values).
enum class LightKind : int32_t { kDirectional = 0, kPoint = 1, kSpot = 2 };

/// a light posed in the world for one snapshot, as plain data (LightSampler::pods()).
struct LightPod {
  LightKind kind = LightKind::kPoint;
  Float3 position_W;                   ///< point, spot
  Float3 direction_W{0, 0, -1};        ///< unit, direction light travels (directional, spot)
  Float3 intensity_rgb;                ///< color x intensity (cd or lux per channel)
  float cos_inner = 1, cos_outer = 1;  ///< spot cone cosines
  float radius_m = 0;                  ///< > 0: a sphere sampled for soft shadows
  float cos_angular_radius = 1;        ///< directional: cosine of the sun disc's angular radius
  int32_t cast_shadow = 1;             ///< 1: trace a shadow ray
};

/// a . b of two 3-vectors of scalar type T: summed (x + y) + z (pbm::Dot, the lanes' and the
/// kernels' order), or with kEigen x + (y + z), as Eigen's fixed-size reduction sums a Vector3f's
/// dot product and squared norm (Eigen 3.4, Redux.h: the terms split in halves).
template <bool kEigen, typename T, typename V>
PB_HOST_DEVICE inline T DotAs(const V& a, const V& b) {
  if constexpr (kEigen) {
    return a.x * b.x + (a.y * b.y + a.z * b.z);
  } else {
    return pbm::Dot<T>(a, b);
  }
}

/// a unit direction sampled uniformly in the cone of cosine `cos_max` around the unit axis w
/// (Pharr, Jakob, Humphreys, "Physically Based Rendering", 4th ed., sec. A.5.4) with the basis
/// of Duff et al. ("Building an orthonormal basis, revisited", JCGT 2017). the axis may be
/// per point (A = T, AV = V) or one for all lanes (A = float, AV = Float3: the basis is then
/// computed once). the direction is normalised by its inverse norm (the lanes' way), or with
/// kEigen (float only) as Eigen's normalized() of a Vector3f: each component divided by the norm
/// where the squared norm (DotAs) is > 0 (the scalar LightSampler::Sample, which the pathtraced
/// tier calls).
template <typename T, typename V, typename A, typename AV, bool kEigen = false>
PB_HOST_DEVICE inline V SampleConeDirection(const AV& w, const A& cos_max, const T& u1,
                                            const T& u2) {
  const T cos_t = 1.0f - u1 * (1.0f - cos_max);
  const T sin_t = pbm::Sqrt(pbm::Max(1.0f - cos_t * cos_t, 0.0f));
  T sp, cp;
  pbm::SinCos2Pi(u2, &sp, &cp);
  const A sign = pbm::SignNonNegative(w.z);
  const A a = -1.0f / (sign + w.z);
  const A b = w.x * w.y * a;
  const AV t{1.0f + sign * w.x * w.x * a, sign * b, -sign * w.x};
  const AV bt{b, sign + w.y * w.y * a, -w.y};
  const T sc = sin_t * cp, ss = sin_t * sp;
  const V d{sc * t.x + ss * bt.x + cos_t * w.x, sc * t.y + ss * bt.y + cos_t * w.y,
            sc * t.z + ss * bt.z + cos_t * w.z};
  if constexpr (kEigen) {
    const T z = DotAs<true, T>(d, d);
    if (!(z > 0.0f)) return d;
    const T n = pbm::Sqrt(z);
    return V{d.x / n, d.y / n, d.z / n};
  } else {
    const T inv = 1.0f / pbm::Sqrt(pbm::Dot<T>(d, d));
    return V{d.x * inv, d.y * inv, d.z * inv};
  }
}

/// one sample of light `l` at world point p_W with uniform numbers u1, u2 in [0, 1) (used by
/// lights with an extent): unit direction *wi towards the light, *distance to the sampled
/// emitter point (+inf for directional lights), illuminance *E (lux per channel) on a surface
/// facing wi, and *valid: false where the light sends nothing to p_W (outside a spot cone,
/// p_W inside the emitter; the other outputs are then unspecified). the model: light_sampler.h.
/// M is bool for float and LaneMask for lanes. kEigen (float only): dot products and the cone
/// direction's normalisation rounded as the Eigen code of the scalar LightSampler::Sample (DotAs,
/// SampleConeDirection), whose bits it then gives; else as the lanes' code.
template <typename T, typename V, typename M, bool kEigen = false>
PB_HOST_DEVICE inline void SampleLight(const LightPod& l, const V& p_W, const T& u1, const T& u2,
                                       V* wi, T* distance, V* E, M* valid) {
  if (l.kind == LightKind::kDirectional) {
    const Float3 to_light = -l.direction_W;
    if (l.cos_angular_radius < 1.0f) {
      *wi =
          SampleConeDirection<T, V, float, Float3, kEigen>(to_light, l.cos_angular_radius, u1, u2);
    } else {
      *wi = V{pbm::Splat<T>(to_light.x), pbm::Splat<T>(to_light.y), pbm::Splat<T>(to_light.z)};
    }
    *distance = pbm::Splat<T>(INFINITY);
    *E = V{pbm::Splat<T>(l.intensity_rgb.x), pbm::Splat<T>(l.intensity_rgb.y),
           pbm::Splat<T>(l.intensity_rgb.z)};
    *valid = pbm::GreaterThan(pbm::Splat<T>(1.0f), 0.0f);
    return;
  }
  const V to_light{l.position_W.x - p_W.x, l.position_W.y - p_W.y, l.position_W.z - p_W.z};
  const T d2 = DotAs<kEigen, T>(to_light, to_light);
  const T d = pbm::Sqrt(d2);
  *valid = pbm::GreaterThan(d, l.radius_m);
  T atten = pbm::Splat<T>(1.0f);
  if (l.kind == LightKind::kSpot) {
    T cos_axis;
    if constexpr (kEigen) {
      cos_axis = -(to_light.x * l.direction_W.x +
                   (to_light.y * l.direction_W.y + to_light.z * l.direction_W.z)) /
                 d;
    } else {
      cos_axis = -(to_light.x * l.direction_W.x + to_light.y * l.direction_W.y +
                   to_light.z * l.direction_W.z) /
                 d;
    }
    if (l.cos_inner <= l.cos_outer) {
      // a hard step where the cone has no soft edge.
      atten = pbm::StepGreaterEqual(cos_axis, l.cos_outer);
    } else {
      // cubic smoothstep from cos(outer) to cos(inner) (glTF KHR_lights_punctual, Filament).
      const T t = pbm::Clamp((cos_axis - l.cos_outer) / (l.cos_inner - l.cos_outer), 0.0f, 1.0f);
      atten = t * t * (3.0f - 2.0f * t);
    }
    *valid = *valid && pbm::GreaterThan(atten, 0.0f);
  }
  const T scale = atten / d2;
  *E = V{l.intensity_rgb.x * scale, l.intensity_rgb.y * scale, l.intensity_rgb.z * scale};
  const T inv_d = 1.0f / d;
  const V w{to_light.x * inv_d, to_light.y * inv_d, to_light.z * inv_d};
  if (l.radius_m > 0) {
    // uniform direction in the cone the sphere subtends, ending on its near surface: for a
    // sphere of uniform radiance I / (pi r^2) each direction carries the full I / d^2.
    const T sin2 = (l.radius_m * l.radius_m) / d2;
    const T cos_max = pbm::Sqrt(pbm::Max(1.0f - sin2, 0.0f));
    *wi = SampleConeDirection<T, V, T, V, kEigen>(w, cos_max, u1, u2);
    // distance to the sphere along wi: the nearer root of |p + t wi - c|^2 = r^2.
    const T b = DotAs<kEigen, T>(*wi, to_light);
    const T disc = pbm::Max(b * b - (d2 - l.radius_m * l.radius_m), 0.0f);
    *distance = pbm::Max(b - pbm::Sqrt(disc), 0.0f);
  } else {
    *wi = w;
    *distance = d;
  }
}

}  // namespace penumbra
