#pragma once
// the pathtraced tier's light terms as PB_HOST_DEVICE functions over plain data, called by its
// one chain (render/transport/path_trace.h, which both backends run): the power heuristic of
// multiple importance sampling, the lamp spheres (point and spot lights with a radius that cast
// shadows: their radiance, solid angle and ray intersection) and the sun discs (directional lights
// with an angular radius). the model is documented in render/transport/path_trace.h. every
// expression keeps the operation order of the Eigen code it replaced (render/shading_math.h's
// bit-for-bit rule; dot products and squared norms as Eigen sums them, EigenDot).

#include <cmath>

#include "penumbra/core/host_device.h"
#include "penumbra/render/light/bsdf_math.h"
#include "penumbra/render/light/light_math.h"
#include "penumbra/render/shading_math.h"

namespace penumbra {

/// power heuristic with beta = 2 (Veach 1997, eq. 9.13) for a sample drawn with density pdf_a,
/// the other strategy having density pdf_b: pdf_a^2 / (pdf_a^2 + pdf_b^2); 0 where pdf_a is
/// not > 0, 1 where it is infinite (a delta strategy), 0 where pdf_b^2 is.
PB_HOST_DEVICE inline float PowerHeuristic(float pdf_a, float pdf_b) {
  if (!(pdf_a > 0)) return 0.0f;
  if (pdf_a == INFINITY) return 1.0f;
  const float a = pdf_a * pdf_a, b = pdf_b * pdf_b;
  if (b == INFINITY) return 0.0f;
  return a / (a + b);
}

/// 1 - cos(theta_max) of the cone a sphere of radius r subtends at centre distance d > r
/// (sin^2 / (1 + cos), accurate for small cones).
PB_HOST_DEVICE inline float OneMinusCosCone(float r, float d) {
  const float sin2 = pbm::Min(1.0f, (r * r) / (d * d));
  return sin2 / (1.0f + sqrtf(pbm::Max(0.0f, 1.0f - sin2)));
}

/// cubic smoothstep from e0 (0) to e1 (1); a hard step at e0 where e1 <= e0 (a spot light's
/// cone edge, as LightSampler's).
PB_HOST_DEVICE inline float SpotSmoothStep(float e0, float e1, float x) {
  if (e1 <= e0) return x >= e0 ? 1.0f : 0.0f;
  const float t = pbm::Clamp((x - e0) / (e1 - e0), 0.0f, 1.0f);
  return t * t * (3.0f - 2.0f * t);
}

/// whether light l is a lamp sphere of the pathtraced tier: a point or spot light with a radius
/// that casts shadows (rays can hit it).
PB_HOST_DEVICE inline bool IsLampSphere(const LightPod& l) {
  return l.cast_shadow != 0 && l.kind != LightKind::kDirectional && l.radius_m > 0;
}

/// the radiance (cd/m^2) lamp sphere l sends towards world point p: I s / (pi r^2), s the spot
/// factor of the direction from its centre to p (1 for point lights).
PB_HOST_DEVICE inline Float3 LampRadianceTowards(const LightPod& l, const Float3& p) {
  float atten = 1.0f;
  if (l.kind == LightKind::kSpot) {
    const Float3 d{p.x - l.position_W.x, p.y - l.position_W.y, p.z - l.position_W.z};
    const float n = sqrtf(EigenDot(d, d));
    if (!(n > 0)) return Float3{};
    atten = SpotSmoothStep(l.cos_outer, l.cos_inner, EigenDot(d, l.direction_W) / n);
  }
  const float s = atten / (pbm::kPi * l.radius_m * l.radius_m);
  return Float3{l.intensity_rgb.x * s, l.intensity_rgb.y * s, l.intensity_rgb.z * s};
}

/// the solid angle (sr) of lamp sphere l seen from world point p outside it; 0 from inside.
PB_HOST_DEVICE inline float LampSolidAngle(const LightPod& l, const Float3& p) {
  const Float3 c{l.position_W.x - p.x, l.position_W.y - p.y, l.position_W.z - p.z};
  const float d = sqrtf(EigenDot(c, c));
  if (!(d > l.radius_m)) return 0.0f;
  return 2 * pbm::kPi * OneMinusCosCone(l.radius_m, d);
}

/// the nearest t in (tmin, tmax) where the ray o + t d (d unit) meets lamp sphere l from
/// outside (the discriminant from the closest approach: Pharr, Jakob, Humphreys, "Physically
/// Based Rendering", 4th ed., 6.8.1); false for none, or an origin inside the sphere.
PB_HOST_DEVICE inline bool LampIntersect(const LightPod& l, const Float3& o, const Float3& d,
                                         float tmin, float tmax, float* t) {
  const float r = l.radius_m;
  const Float3 oc{o.x - l.position_W.x, o.y - l.position_W.y, o.z - l.position_W.z};
  const float c2 = EigenDot(oc, oc) - r * r;
  if (c2 <= 0) return false;  // origin inside the lamp
  const float b = EigenDot(oc, d);
  if (b >= 0) return false;  // sphere behind
  const Float3 q{oc.x - b * d.x, oc.y - b * d.y, oc.z - b * d.z};
  const float disc = r * r - EigenDot(q, q);
  if (disc < 0) return false;
  const float root = -b - sqrtf(disc);
  if (!(root > tmin && root < tmax)) return false;
  *t = root;
  return true;
}

/// a directional light with an angular radius that casts shadows, as a disc in the sky.
struct SunDiscPod {
  Float3 to_sun{0, 0, 1};  ///< unit, towards the sun
  float cos_max = 1;       ///< cosine of the angular radius
  float solid_angle = 0;   ///< 2 pi (1 - cos_max), sr
  Float3 L;                ///< radiance E / solid_angle, cd/m^2
};

/// the sun disc of light l; false where l is none (not directional, casts no shadow, no
/// angular radius, or a zero solid angle).
PB_HOST_DEVICE inline bool SunDiscOf(const LightPod& l, SunDiscPod* s) {
  if (l.cast_shadow == 0 || l.kind != LightKind::kDirectional) return false;
  if (!(l.cos_angular_radius < 1.0f)) return false;
  s->to_sun = -l.direction_W;
  s->cos_max = l.cos_angular_radius;
  s->solid_angle = 2 * pbm::kPi * (1.0f - l.cos_angular_radius);
  if (!(s->solid_angle > 0)) return false;
  s->L = Float3{l.intensity_rgb.x / s->solid_angle, l.intensity_rgb.y / s->solid_angle,
                l.intensity_rgb.z / s->solid_angle};
  return true;
}

}  // namespace penumbra
