#pragma once
// direct light from lights with an extent (spherical lamps, the sun's disc) without per-pixel
// noise, written once for both processors (PB_HOST_DEVICE, core/host_device.h; plain floats and
// float[3], no Eigen, so that device code can include it: /work/coord/shading_contract.md's
// rules; the CPU calls these per lane). used by the realtime tier
// (render/cpu/realtime_integrator.cc):
//
//   unshadowed:  the illuminance of a uniformly emitting sphere of angular radius sigma (sin^2
//                sigma = r^2 / d^2; a disc facing the point, such as the sun's, gives the same
//                value) on a surface whose normal is theta from the sphere's centre, clipped by
//                the surface's horizon, in closed form (Snyder, "Area light sources for
//                real-time graphics", Microsoft Research MSR-TR-96-11, 1996; in the form of
//                Lagarde and de Rousiers, "Moving Frostbite to physically based rendering",
//                SIGGRAPH 2014 course, sec. 4.7.2, listing 7):
//                  E = (I / d^2) SphereLightCosine(cos theta, sin^2 sigma)
//                with SphereLightCosine = max(cos theta, 0) while the sphere is wholly above or
//                below the horizon (cos^2 theta >= sin^2 sigma; exact), else the clipped form.
//   visibility:  the fraction of the light's cone that is unoccluded, estimated by spatial
//                reuse: pixel (u, v) traces one shadow ray through point LightStratum(u, v) of
//                a 16-point spherical Fibonacci lattice over the cone (Gonzalez, "Measurement
//                of areas on a sphere using Fibonacci and latitude-longitude lattices", Math.
//                Geosci. 42, 2010), so that every 4x4 block of pixels covers all 16 points, and
//                the pixel's visibility is the mean over the 4x4 window around it of the
//                neighbours that lie on the same surface (the ratio estimator of Heitz, Hill
//                and McGuire, "Combining analytic direct illumination and stochastic shadows",
//                I3D 2018, with the shadow term shared across a window instead of denoised).
//                fixed points: no random numbers, the same picture every frame (no flicker).

#include <cmath>

#include "penumbra/core/host_device.h"
#include "penumbra/render/shading_math.h"

namespace penumbra {

/// points of the visibility lattice over a light's cone (one per pixel of a 4x4 block).
constexpr int kLightStrata = 16;
/// shadow rays per pixel towards a light with an extent in a penumbra (the CPU's shared
/// visibility; the CUDA path traces all of them at every pixel).
constexpr int kLightPenumbraRays = 4;

/// a light's share of a pixel's unshadowed luminance at or above which a pixel in its penumbra
/// traces all kLightStrata kLightPenumbraRays (64) lattice points (PenumbraLatticePoints).
constexpr float kPenumbraShareAllPoints = 0.5f;
/// the share at or above which it traces half of them (32).
constexpr float kPenumbraShareHalfPoints = 0.25f;
/// the share at or above which it traces kLightStrata (16) of them; below, kLightPenumbraRays.
constexpr float kPenumbraShareStrata = 1.0f / 16.0f;

/// the factor c with which a sphere of intensity I (cd) at distance d, subtending angular radius
/// sigma (sin2_sigma = sin^2 sigma, in [0, 1)), lights a surface whose unit normal makes angle
/// theta with the direction to the sphere's centre: E = (I / d^2) c, lux (Snyder 1996, see
/// above). c = max(cos_theta, 0) when the sphere lies wholly on one side of the surface's
/// horizon; in between, the lit part of the sphere (c > 0 for cos_theta > -sin sigma). for the
/// sun's disc (directional light of angular radius sigma) E = E_sun c.
PB_HOST_DEVICE inline float SphereLightCosine(float cos_theta, float sin2_sigma) {
  if (cos_theta * cos_theta >= sin2_sigma || !(sin2_sigma > 0))
    return cos_theta > 0 ? cos_theta : 0;
  if (sin2_sigma >= 1.0f) return 1.0f;  // the point is on the sphere: a lit hemisphere
  constexpr float kPi = 3.14159265358979323846f;
  const float sin_theta = sqrtf(fmaxf(0.0f, 1.0f - cos_theta * cos_theta));
  const float x = sqrtf(1.0f / sin2_sigma - 1.0f);  // cot sigma
  const float y = fminf(1.0f, fmaxf(-1.0f, -x * cos_theta / sin_theta));
  const float s = sin_theta * sqrtf(fmaxf(0.0f, 1.0f - y * y));
  const float f = (cos_theta * acosf(y) - x * s) * sin2_sigma + atanf(s / x);
  return fmaxf(f, 0.0f) / (kPi * sin2_sigma);
}

/// the cosine, with the surface normal, of the direction at which the BRDF is evaluated for a
/// sphere straddling the horizon: the middle of the sphere's part above it, (cos_theta + sin
/// sigma) / 2; cos_theta itself while the sphere is wholly above it.
PB_HOST_DEVICE inline float SphereLightShadingCosine(float cos_theta, float sin2_sigma) {
  const float sin_sigma = sqrtf(fmaxf(sin2_sigma, 0.0f));
  return cos_theta >= sin_sigma ? cos_theta : 0.5f * (cos_theta + sin_sigma);
}

/// unit direction whose cosine with unit normal n is cos_target, in the plane of unit w (the
/// direction to the light's centre) and n, on w's side: w turned towards n. writes it to out.
/// w parallel to n gives w.
PB_HOST_DEVICE inline void TiltTowardsNormal(const float w[3], const float n[3], float cos_target,
                                             float out[3]) {
  const float c = w[0] * n[0] + w[1] * n[1] + w[2] * n[2];
  float t[3] = {w[0] - c * n[0], w[1] - c * n[1], w[2] - c * n[2]};
  const float tl = sqrtf(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
  if (!(tl > 1e-7f)) {
    out[0] = w[0], out[1] = w[1], out[2] = w[2];
    return;
  }
  const float st = sqrtf(fmaxf(0.0f, 1.0f - cos_target * cos_target)) / tl;
  for (int i = 0; i < 3; ++i) out[i] = cos_target * n[i] + st * t[i];
}

/// the direction w (unit, towards the centre), sin^2 sigma and the distance to the near side
/// of a spherical lamp of radius r centred at c, seen from point p (all world frame, m):
/// d = |c - p|, sin^2 sigma = min(1, r^2 / d^2), near = max(d - r, 0). p at the centre gives
/// w = 0 and sin^2 sigma = 1.
PB_HOST_DEVICE inline void SphereLightAxis(const float c[3], float r, const float p[3], float w[3],
                                           float* sin2_sigma, float* near_m) {
  const float t[3] = {c[0] - p[0], c[1] - p[1], c[2] - p[2]};
  const float d2 = t[0] * t[0] + t[1] * t[1] + t[2] * t[2];
  const float d = sqrtf(d2);
  const float inv = d > 0 ? 1.0f / d : 0.0f;
  for (int i = 0; i < 3; ++i) w[i] = t[i] * inv;
  *sin2_sigma = d2 > 0 ? fminf(1.0f, r * r / d2) : 1.0f;
  *near_m = fmaxf(d - r, 0.0f);
}

/// whether a light has an extent whose light and shadows the realtime tier treats in closed
/// form: a directional light with a sun disc (cos of its angular radius < 1) or a lamp with a
/// radius > 0.
PB_HOST_DEVICE inline bool HasLightExtent(bool directional, float cos_angular_radius,
                                          float radius_m) {
  return directional ? cos_angular_radius < 1.0f : radius_m > 0;
}

/// whether a light of angular radius sigma (sin^2 sigma, sin sigma) around a direction at
/// cos_t to the shading normal straddles the horizon, so that ExtendedLightShading must tilt
/// it (else it lies wholly above, factor 1, or wholly below, factor 0). a point whose cos^2
/// rounds to >= sin^2 sigma but cos to < sin sigma counts as straddling, as
/// ExtendedLightShading would treat it.
/// for a float (M bool) or every lane of Lanes (M LaneMask), by the same comparisons of the same
/// values (a NaN straddles).
template <typename T, typename M>
PB_HOST_DEVICE inline M LightStraddlesHorizonOf(const T& cos_t, const T& sin2_sigma,
                                                const T& sin_sigma) {
  const T cos2 = cos_t * cos_t;
  const M wholly = (pbm::GreaterEqual(cos2, sin2_sigma) || !pbm::GreaterThan(sin2_sigma, 0.0f)) &&
                   !(pbm::GreaterThan(cos_t, 0.0f) && pbm::GreaterThan(sin_sigma, cos_t));
  return !wholly;
}
/// LightStraddlesHorizonOf of one point.
PB_HOST_DEVICE inline bool LightStraddlesHorizon(float cos_t, float sin2_sigma, float sin_sigma) {
  return LightStraddlesHorizonOf<float, bool>(cos_t, sin2_sigma, sin_sigma);
}

/// how a light of angular radius sigma around unit direction w is shaded at a point with unit
/// shading normal n: writes the direction wi (unit) at which to evaluate the BRDF, f(wo, wi)
/// |n . wi| (w, or w tilted above the horizon, TiltTowardsNormal to SphereLightShadingCosine)
/// and returns the factor s such that the light's contribution is f(wo, wi) |n . wi| E s,
/// E = I / d^2 (or E_sun): s = SphereLightCosine / SphereLightShadingCosine (1 while the light
/// is wholly above the horizon, 0 below it).
PB_HOST_DEVICE inline float ExtendedLightShading(const float w[3], float sin2_sigma,
                                                 const float n[3], float wi[3]) {
  const float cos_t = w[0] * n[0] + w[1] * n[1] + w[2] * n[2];
  const float c_eff = SphereLightCosine(cos_t, sin2_sigma);
  const float c_rep = SphereLightShadingCosine(cos_t, sin2_sigma);
  wi[0] = w[0], wi[1] = w[1], wi[2] = w[2];
  if (c_rep != cos_t) TiltTowardsNormal(w, n, c_rep, wi);
  return c_eff > 0 && c_rep > 1e-6f ? c_eff / c_rep : 0.0f;
}

/// the lattice point of pixel (u, v) (image column, row >= 0), in [0, kLightStrata): a 4x4
/// ordered-dither (Bayer) index, so that every 4x4 block holds each point once and every 2x2
/// block four points spread over the cone.
PB_HOST_DEVICE inline int LightStratum(int u, int v) {
  constexpr int kBayer4[16] = {0, 8, 2, 10, 12, 4, 14, 6, 3, 11, 1, 9, 15, 7, 13, 5};
  return kBayer4[(v & 3) * 4 + (u & 3)];
}

/// the two uniform numbers of point `index` of a spherical Fibonacci lattice of `count` points
/// over a cone, as LightSampler::Sample takes them (u1: 1 - cos of the angle from the axis,
/// equal-area; u2: the turn around it): u1 = (index + 1/2) / count, u2 = frac(index / golden
/// ratio). the points index = m k (k = 0, 1, ...) of a lattice of m kLightStrata points spread
/// over the whole cone too. (a per-pixel offset of the lattice, tried, made streaks: the
/// offsets of neighbouring pixels correlate with the 4x4 assignment.)
PB_HOST_DEVICE inline void LightStratumUniforms(int index, int count, float* u1, float* u2) {
  constexpr float kInvGolden = 0.6180339887498949f;
  *u1 = (static_cast<float>(index) + 0.5f) / static_cast<float>(count);
  const float a = static_cast<float>(index) * kInvGolden;
  *u2 = a - floorf(a);
}

/// the shadow-ray budget of a pixel in the penumbra of a light with an extent: how many points of
/// the kLightStrata kLightPenumbraRays (64) point lattice decide the pixel's visibility of the
/// light, given the light's share of the pixel's unshadowed luminance (share = Y(f E) / Y(L),
/// Y the Rec. 709 luminance, L the pixel's radiance with every light unshadowed, in [0, 1]):
/// 64 at share >= kPenumbraShareAllPoints (1/2), 32 at share >= kPenumbraShareHalfPoints (1/4),
/// 16 at share >= kPenumbraShareStrata (1/16), else kLightPenumbraRays (4). one point of a lattice
/// of N moves the pixel's luminance by about share / N, which so stays below about 1/64 (the step
/// of a light that alone lights the pixel with all 64 points): a faint lamp's penumbra needs few
/// rays. a NaN share counts as 0. the CPU's shared visibility (render/cpu/realtime_integrator.cc)
/// traces max(1, N / 16) points per pixel of a window of 16, or N points of its own at a tile's
/// edge; a pixel that traces all its points itself (the CUDA path) traces N.
PB_HOST_DEVICE inline int PenumbraLatticePoints(float share) {
  if (share >= kPenumbraShareAllPoints) return kLightStrata * kLightPenumbraRays;
  if (share >= kPenumbraShareHalfPoints) return kLightStrata * kLightPenumbraRays / 2;
  if (share >= kPenumbraShareStrata) return kLightStrata;
  return kLightPenumbraRays;
}

/// the index (into the kLightStrata kLightPenumbraRays point lattice, LightStratumUniforms) of
/// point r, 0 <= r < points, of a pixel that traces `points` (64, 16 or 4: PenumbraLatticePoints)
/// points of its own, starting at its own point `first` = kLightPenumbraRays LightStratum(u, v):
/// every (64 / points)-th point from `first`, so that any budget spreads over the whole cone
/// (for 64, the points first, first + 1, ...; for 32, the even points; for 16, the points of the
/// 16-point lattice; for 4, one per quarter of the cone's solid angle).
PB_HOST_DEVICE inline int PenumbraLatticeIndex(int first, int r, int points) {
  constexpr int kAll = kLightStrata * kLightPenumbraRays;
  return (first + r * (kAll / points)) % kAll;
}

}  // namespace penumbra
