#pragma once
// the homogeneous media's closed forms as PB_HOST_DEVICE functions, for both tiers and both
// processors (render/media/media_realtime_math.h's per-pixel formulas and
// render/media/media_scene_math.h's path tracing build on them):
//  - MediaSlabInterval: the part of a ray inside a box (AnalyticMedium::Interval,
//    GridVolume::Interval); MediumInterval: the part inside a homogeneous medium;
//  - DensityIntegralF: the closed-form integral of a height-falloff density along a camera ray
//    in single precision; MediaDensityIntegral / MediaInvertDensityIntegral (double): the same
//    integral and its inverse over the pieces below and above the base height (MediaPieces),
//    as AnalyticMedium computes them for both tiers;
//  - MediaPhaseHG: the Henyey-Greenstein phase function;
//  - AnalyticOpticalDepthOf: the media's rgb optical depth (MediaScene::AnalyticOpticalDepth).
// operation order: the CPU's, bit for bit (the rule of shading_math.h).

#include <math.h>

#include "penumbra/core/host_device.h"
#include "penumbra/render/shading_math.h"

namespace penumbra {
/// x (float or double) is +inf or -inf (std::isinf).
template <typename T>
PB_HOST_DEVICE inline bool MediaIsInf(T x) {
#if defined(__CUDA_ARCH__)
  return isinf(x);
#else
  return __builtin_isinf(x);
#endif
}

/// std::min / std::max of two ints.
PB_HOST_DEVICE inline int MediaMinI(int a, int b) { return b < a ? b : a; }
PB_HOST_DEVICE inline int MediaMaxI(int a, int b) { return a < b ? b : a; }

/// the part [a, b] of [t0, t1] where o + t d lies in the box [lo_b, hi_b] (3 floats each;
/// slabs, an axis with |d| < 1e-12 tested by o alone); false if empty.
PB_HOST_DEVICE inline bool MediaSlabInterval(const float* o, const float* d, const float* lo_b,
                                             const float* hi_b, float t0, float t1, float* a,
                                             float* b) {
  float lo = t0, hi = t1;
  for (int k = 0; k < 3; ++k) {
    if (fabsf(d[k]) < 1e-12f) {
      if (o[k] < lo_b[k] || o[k] > hi_b[k]) return false;
      continue;
    }
    const float inv = 1.0f / d[k];
    float ta = (lo_b[k] - o[k]) * inv, tb = (hi_b[k] - o[k]) * inv;
    if (ta > tb) {
      const float s = ta;
      ta = tb;
      tb = s;
    }
    lo = pbm::Max(lo, ta);
    hi = pbm::Min(hi, tb);
  }
  if (!(lo < hi)) return false;
  *a = lo;
  *b = hi;
  return true;
}

/// the integral of a density h_s exp(-rate (t - s)) over [s, e] (rate 0: constant; e may be
/// +inf), DensityIntegralF's piece.
PB_HOST_DEVICE inline float MediaDensityPiece(float s, float e, float h_s, float rate) {
  const float len = e - s;
  if (rate == 0.0f || fabsf(rate) * len < 1e-6f) return h_s * len;
  if (MediaIsInf(len)) return rate > 0 ? h_s / rate : INFINITY;
  return h_s * -expm1f(-rate * len) / rate;
}

/// the relative density h(z(t)) = exp(-k max(0, oz + dz t - zb)) of DensityIntegralF, h_0 at
/// t = 0 when h_0 is not NaN.
PB_HOST_DEVICE inline float MediaDensityAlong(float k, float zb, float oz, float dz, float t,
                                              float h_0) {
  if (t == 0.0f && h_0 == h_0) return h_0;
  return expf(-k * pbm::Max(0.0f, oz + dz * t - zb));
}

/// AnalyticMedium::DensityIntegral in single precision for camera rays (the same pieces below
/// and above the base height, closed form per piece): the integral of h(z(t)) dt over [a, b]
/// for z(t) = oz + dz t (d unit) of a medium of height falloff k (1/m, 0 uniform) and base
/// height zb (m); b may be +inf. float keeps the relative error near 1e-6 (the optical depths
/// it yields are used as exp(-tau) for display radiance). h_0: h(0) of this ray (the camera's h,
/// MediumPod::h_cam) when oz is the camera's height, else NaN (then computed here); h(+-0)
/// does not depend on dz, so it is the same value bit for bit.
PB_HOST_DEVICE inline float DensityIntegralF(float k, float zb, float oz, float dz, float a,
                                             float b, float h_0) {
  if (!(a < b)) return 0.0f;
  if (k <= 0 || fabsf(dz) < 1e-9f)
    return MediaDensityPiece(a, b, k <= 0 ? 1.0f : MediaDensityAlong(k, zb, oz, dz, a, h_0), 0.0f);
  const float tc = (zb - oz) / dz;  // where z crosses the base
  float sum = 0.0f;
  if (dz > 0) {
    if (a < tc) sum += MediaDensityPiece(a, pbm::Min(b, tc), 1.0f, 0.0f);
    const float s = pbm::Max(a, tc);
    if (s < b) sum += MediaDensityPiece(s, b, MediaDensityAlong(k, zb, oz, dz, s, h_0), k * dz);
  } else {
    if (a < tc)
      sum +=
          MediaDensityPiece(a, pbm::Min(b, tc), MediaDensityAlong(k, zb, oz, dz, a, h_0), k * dz);
    const float s = pbm::Max(a, tc);
    if (s < b) sum += MediaDensityPiece(s, b, 1.0f, 0.0f);
  }
  return sum;
}

/// one homogeneous medium (AnalyticMedium) as the per-pixel formulas read it.
struct MediumPod {
  float sigma_t[3] = {0, 0, 0};  ///< 1/m at full density
  float sigma_s[3] = {0, 0, 0};  ///< sigma_t * albedo, 1/m
  float falloff = 0;             ///< height falloff k, 1/m (0 = uniform)
  float base = 0;                ///< world z below which the density is 1
  int bounded = 0;               ///< confined to [box_min, box_max]
  float box_min[3] = {0, 0, 0}, box_max[3] = {0, 0, 0};
  float h_cam = 1;  ///< h(0) for rays from the camera's height (DensityIntegralF's h_0)
  float g = 0;      ///< Henyey-Greenstein asymmetry (the fog froxels' build reads it)
};

/// one piece of a height-fog ray in double precision: density h_s exp(-rate (t - s)) on
/// [s, e] (rate 0: constant); AnalyticMedium::DensityIntegral / InvertDensityIntegral (both
/// tiers' exact optical depths and free-flight sampling) are sums of these.
struct MediaPiece {
  double s, e, h_s, rate;
};

/// 1 / (4 pi).
constexpr float kInv4Pi = 0.0795774715459476679f;

/// Henyey-Greenstein phase function (Henyey and Greenstein, "Diffuse radiation in the
/// galaxy", ApJ 93, 1941; Pharr, Jakob, Humphreys, PBR 4th ed., sec. 11.3.1), normalised
/// over the sphere (1/sr): p(cos_theta) = (1 - g^2) / (4 pi (1 + g^2 + 2 g cos_theta)^1.5),
/// where cos_theta = dot(wo, wi) with wo pointing back along the incoming ray (PBRT's
/// convention), so g > 0 scatters forward. (media_common.h's HenyeyGreenstein.)
PB_HOST_DEVICE inline float MediaPhaseHG(float cos_theta, float g) {
  const float denom = 1.0f + g * g + 2.0f * g * cos_theta;
  return kInv4Pi * (1.0f - g * g) / (denom * sqrtf(pbm::Max(denom, 1e-12f)));
}

/// the integral of piece p over [s, e] (+inf for an infinite piece whose density does not
/// vanish).
PB_HOST_DEVICE inline double MediaPieceIntegral(const MediaPiece& p) {
  const double len = p.e - p.s;
  if (p.rate == 0 || fabs(p.rate) * len < 1e-9) return p.h_s * len;
  if (MediaIsInf(len)) return p.rate > 0 ? p.h_s / p.rate : static_cast<double>(INFINITY);
  return p.h_s * -expm1(-p.rate * len) / p.rate;
}

/// the t in [s, e] of piece p where its integral from s reaches tau (tau <= the integral);
/// +inf where a decaying density never reaches it.
PB_HOST_DEVICE inline double MediaPieceInvert(const MediaPiece& p, double tau) {
  const double len = p.e - p.s;
  if (p.rate == 0 || fabs(p.rate) * (1e30 < len ? 1e30 : len) < 1e-9) return p.s + tau / p.h_s;
  const double x = tau * p.rate / p.h_s;
  if (x >= 1) return static_cast<double>(INFINITY);
  return p.s - log1p(-x) / p.rate;
}

/// splits [a, b] of z(t) = oz + dz t into the pieces below and above the base height zb of a
/// medium of height falloff k (1/m; 0 uniform); returns their number (1 or 2, 0 if none).
PB_HOST_DEVICE inline int MediaPieces(double k, double zb, double oz, double dz, double a, double b,
                                      MediaPiece out[2]) {
  if (k <= 0 || fabs(dz) < 1e-9) {
    const double z = oz + dz * a - zb;
    out[0] = {a, b, k <= 0 ? 1.0 : exp(-k * (0.0 < z ? z : 0.0)), 0.0};
    return 1;
  }
  const double tc = (zb - oz) / dz;  // where z crosses the base
  int n = 0;
  if (dz > 0) {
    if (a < tc) out[n++] = {a, tc < b ? tc : b, 1.0, 0.0};
    const double s = a < tc ? tc : a;
    const double z = oz + dz * s - zb;
    if (s < b) out[n++] = {s, b, exp(-k * (0.0 < z ? z : 0.0)), k * dz};
  } else {
    const double z = oz + dz * a - zb;
    if (a < tc) out[n++] = {a, tc < b ? tc : b, exp(-k * (0.0 < z ? z : 0.0)), k * dz};
    const double s = a < tc ? tc : a;
    if (s < b) out[n++] = {s, b, 1.0, 0.0};
  }
  return n;
}

/// AnalyticMedium::DensityIntegral: the integral of the relative density over [a, b] of
/// z(t) = oz + dz t (d unit; b may be +inf), closed form per piece.
PB_HOST_DEVICE inline double MediaDensityIntegral(double k, double zb, double oz, double dz,
                                                  double a, double b) {
  if (!(a < b)) return 0;
  MediaPiece p[2];
  const int n = MediaPieces(k, zb, oz, dz, a, b, p);
  double sum = 0;
  for (int i = 0; i < n; ++i) sum += MediaPieceIntegral(p[i]);
  return sum;
}

/// AnalyticMedium::InvertDensityIntegral: the t in [a, b] where MediaDensityIntegral from a
/// reaches tau, or +inf if it does not.
PB_HOST_DEVICE inline double MediaInvertDensityIntegral(double k, double zb, double oz, double dz,
                                                        double a, double b, double tau) {
  if (!(a < b)) return static_cast<double>(INFINITY);
  MediaPiece p[2];
  const int n = MediaPieces(k, zb, oz, dz, a, b, p);
  for (int i = 0; i < n; ++i) {
    const double I = MediaPieceIntegral(p[i]);
    if (tau <= I) {
      const double t = MediaPieceInvert(p[i], tau);
      return p[i].e < t ? p[i].e : t;
    }
    tau -= I;
  }
  return static_cast<double>(INFINITY);
}

/// the part [a, b] of [t0, t1] where o + t d is inside medium m; false if empty
/// (AnalyticMedium::Interval).
PB_HOST_DEVICE inline bool MediumInterval(const MediumPod& m, const float* o, const float* d,
                                          float t0, float t1, float* a, float* b) {
  if (!m.bounded) {
    if (!(t0 < t1)) return false;
    *a = t0;
    *b = t1;
    return true;
  }
  return MediaSlabInterval(o, d, m.box_min, m.box_max, t0, t1, a, b);
}

/// the rgb optical depth of the n homogeneous media along o + t d (d unit), t in [t0, t1] (t1
/// may be +inf), in double-precision closed form per medium, each capped at 1e30 before the
/// product (MediaScene::AnalyticOpticalDepth; summed in media order from 0).
PB_HOST_DEVICE inline Float3 AnalyticOpticalDepthOf(const MediumPod* media, int n, const float* o,
                                                    const float* d, float t0, float t1) {
  Float3 tau;
  for (int i = 0; i < n; ++i) {
    const MediumPod& m = media[i];
    float a, b;
    if (!MediumInterval(m, o, d, t0, t1, &a, &b)) continue;
    const double I = MediaDensityIntegral(m.falloff, m.base, o[2], d[2], a, b);
    const float If = static_cast<float>(1e30 < I ? 1e30 : I);  // std::min(I, 1e30)
    tau.x = tau.x + m.sigma_t[0] * If;
    tau.y = tau.y + m.sigma_t[1] * If;
    tau.z = tau.z + m.sigma_t[2] * If;
  }
  return tau;
}

}  // namespace penumbra
