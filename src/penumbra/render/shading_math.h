#pragma once
// the vocabulary of the shading formulas both backends run (the contract:
// docs/gpu.md, "One shading code"). a formula is written once, as a PB_HOST_DEVICE function in
// a render/ root header (brdf_math.h, light_math.h, film_math.h, texture_math.h), and called by
// the CPU backend (render/cpu/) and by the CUDA kernels (render/cuda/*.cu).
//
// types: where the CPU runs a formula on SIMD lanes (render/shading_lanes.h, 16 floats per
// value) the formula is a template over its scalar type T: float on the GPU and in scalar CPU
// code, Lanes in the CPU's lane code; a 3-vector is any struct with members x, y, z of type T
// (Float3 here, Vec3Lanes there). the helpers below (Min, Max, Clamp, Sqrt, Select, ...) have
// float overloads here and Lanes overloads of the same names in shading_lanes.h (host only),
// so that one template body serves both. no Eigen (device code is C++17 and Eigen-free) and no
// standard library containers or exceptions.
//
// bit-for-bit rule: a formula keeps the operation order of the CPU code it replaced; the build
// uses -ffp-contract=off on the host (no fused multiply-adds), so the CPU images do not change.
// nvcc contracts a * b + c into FMAs by default: the GPU's results differ from the CPU's by
// float rounding only.

#include <cmath>

#include "penumbra/core/host_device.h"

namespace penumbra {

/// a float 3-vector for device and scalar host code (x = r, y = g, z = b for colours).
struct Float3 {
  float x = 0, y = 0, z = 0;
};

PB_HOST_DEVICE inline Float3 operator+(const Float3& a, const Float3& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
PB_HOST_DEVICE inline Float3 operator-(const Float3& a, const Float3& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
PB_HOST_DEVICE inline Float3 operator-(const Float3& a) { return {-a.x, -a.y, -a.z}; }
PB_HOST_DEVICE inline Float3 operator*(const Float3& a, float s) {
  return {a.x * s, a.y * s, a.z * s};
}
PB_HOST_DEVICE inline Float3 operator*(float s, const Float3& a) {
  return {s * a.x, s * a.y, s * a.z};
}

namespace pbm {

constexpr float kPi = 3.14159265358979323846f;
constexpr float kInvPi = 0.318309886183790671538f;

/// the smaller / larger of a and b as std::min / std::max take them (b < a ? b : a); float or
/// double, both arguments of one type (no conversion hidden in a call).
template <typename T>
PB_HOST_DEVICE inline T Min(T a, T b) {
  return b < a ? b : a;
}
template <typename T>
PB_HOST_DEVICE inline T Max(T a, T b) {
  return a < b ? b : a;
}
/// std::clamp(x, lo, hi): x < lo ? lo : (hi < x ? hi : x).
template <typename T>
PB_HOST_DEVICE inline T Clamp(T x, T lo, T hi) {
  return x < lo ? lo : (hi < x ? hi : x);
}
PB_HOST_DEVICE inline float Sqrt(float x) { return sqrtf(x); }
PB_HOST_DEVICE inline float Abs(float x) { return fabsf(x); }
PB_HOST_DEVICE inline float Exp(float x) { return expf(x); }
/// x is neither infinite nor NaN.
PB_HOST_DEVICE inline bool IsFinite(float x) {
#if defined(__CUDA_ARCH__)
  return isfinite(x);
#else
  return std::isfinite(x);
#endif
}
/// c ? a : b.
PB_HOST_DEVICE inline float Select(bool c, float a, float b) { return c ? a : b; }
/// c0 > 0 && c1 > 0 && c2 > 0 ? a : +0 (the lanes' WhereAllPositive).
PB_HOST_DEVICE inline float WhereAllPositive(float c0, float c1, float c2, float a) {
  return (c0 > 0.0f && c1 > 0.0f && c2 > 0.0f) ? a : 0.0f;
}
/// x >= e ? 1 : 0.
PB_HOST_DEVICE inline float StepGreaterEqual(float x, float e) { return x >= e ? 1.0f : 0.0f; }
/// a > b (LaneMask for lanes).
PB_HOST_DEVICE inline bool GreaterThan(float a, float b) { return a > b; }
/// a >= b (LaneMask for lanes).
PB_HOST_DEVICE inline bool GreaterEqual(float a, float b) { return a >= b; }
/// x > e ? 1 : 0.
PB_HOST_DEVICE inline float StepGreaterThan(float x, float e) { return x > e ? 1.0f : 0.0f; }
/// c > 0 ? a : b.
PB_HOST_DEVICE inline float WherePositiveElse(float c, float a, float b) {
  return c > 0.0f ? a : b;
}
/// m ? a : +0 (the lanes' Where: +0 in unselected lanes).
PB_HOST_DEVICE inline float Where(bool m, float a) { return m ? a : 0.0f; }
/// lane k of x (a float has one lane, k = 0).
PB_HOST_DEVICE inline float& LaneOf(float& x, int) { return x; }
PB_HOST_DEVICE inline float LaneOf(const float& x, int) { return x; }
/// calls fn(k) for every lane k set in m (a bool: fn(0) where true), lowest lane first: the
/// scalar work a formula does on a few lanes (a light straddling the horizon).
template <typename F>
PB_HOST_DEVICE inline void ForEachLane(bool m, F&& fn) {
  if (m) fn(0);
}
/// a value of type T with every lane x (float: x).
template <typename T>
PB_HOST_DEVICE inline T Splat(float x);
template <>
PB_HOST_DEVICE inline float Splat<float>(float x) {
  return x;
}
/// +1 where x >= 0, else -1.
PB_HOST_DEVICE inline float SignNonNegative(float x) { return x >= 0 ? 1.0f : -1.0f; }

/// a . b for any two 3-vectors of one scalar type (x * x + y * y + z * z order).
template <typename T, typename V>
PB_HOST_DEVICE inline T Dot(const V& a, const V& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}

/// Rec. 709 luminance (IEC 61966-2-1 weights) of a linear rgb value.
template <typename T>
PB_HOST_DEVICE inline T Luminance709(const T& r, const T& g, const T& b) {
  return 0.2126f * r + 0.7152f * g + 0.0722f * b;
}

/// sin(2 pi u) and cos(2 pi u) for u in [0, 1): quadrant from 4u, then Taylor polynomials of
/// degree 7 / 8 on [-pi/4, pi/4] rotated by pi/4 (absolute error < 1e-6). branch-free, so that
/// loops over lanes vectorise.
PB_HOST_DEVICE inline void SinCos2Pi(float u, float* s, float* c) {
  const int q = static_cast<int>(u * 4.0f);  // quadrant 0..3 (u >= 0)
  const float x = (u * 4.0f - static_cast<float>(q) - 0.5f) * 1.5707963267948966f;  // [-pi/4, pi/4)
  const float x2 = x * x;
  const float sx = x * (1.0f + x2 * (-1.0f / 6 + x2 * (1.0f / 120 + x2 * (-1.0f / 5040))));
  const float cx =
      1.0f + x2 * (-0.5f + x2 * (1.0f / 24 + x2 * (-1.0f / 720 + x2 * (1.0f / 40320))));
  // angle within the quadrant = x + pi/4.
  constexpr float kH = 0.70710678118654752f;
  const float sr = (sx + cx) * kH, cr = (cx - sx) * kH;
  // rotate by q quarter turns: odd quadrants swap sin and cos; cos < 0 in quadrants 1, 2 and
  // sin < 0 in quadrants 2, 3.
  const bool odd = (q & 1) != 0;
  const float a = odd ? sr : cr, b = odd ? cr : sr;
  *c = (q == 1 || q == 2) ? -a : a;
  *s = q >= 2 ? -b : b;
}

}  // namespace pbm
}  // namespace penumbra

// the Lanes overloads of the helpers above (host only): declared before any formula template
// is defined, so that the templates find them (two-phase lookup of qualified names).
#if !defined(__CUDACC__)
#include "penumbra/render/shading_lanes.h"
#endif
