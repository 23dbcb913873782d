#pragma once
// structure-of-arrays math for shading kLanes points at once (the realtime tier shades a row
// of 16 pixels together, matching Embree's 16-wide ray packets). Eigen's fixed-size arrays
// compile to SIMD instructions; masks are arrays of bool and every lane computes every branch.
//
// SinCos2Pi is shared by the scalar and the lane code, so both sample the same directions.

#include <Eigen/Core>
#include <cmath>

namespace penumbra {

/// lanes per shading batch (= Embree packet width used by the renderer).
constexpr int kLanes = 16;

/// one float per lane.
using Lanes = Eigen::Array<float, kLanes, 1>;
/// one bool per lane.
using LaneMask = Eigen::Array<bool, kLanes, 1>;

/// a 3-vector per lane.
struct Vec3Lanes {
  Lanes x, y, z;

  Lanes Dot(const Vec3Lanes& o) const { return x * o.x + y * o.y + z * o.z; }
  Vec3Lanes operator+(const Vec3Lanes& o) const { return {x + o.x, y + o.y, z + o.z}; }
  Vec3Lanes operator-(const Vec3Lanes& o) const { return {x - o.x, y - o.y, z - o.z}; }
  Vec3Lanes operator*(const Lanes& s) const { return {x * s, y * s, z * s}; }
  Vec3Lanes operator-() const { return {-x, -y, -z}; }
  /// lane k as a vector.
  Eigen::Vector3f Lane(int k) const { return {x[k], y[k], z[k]}; }
  /// sets lane k.
  void Set(int k, const Eigen::Vector3f& v) {
    x[k] = v.x();
    y[k] = v.y();
    z[k] = v.z();
  }
};

/// sin(2 pi u) and cos(2 pi u) for u in [0, 1): quadrant from 4u, then Taylor polynomials of
/// degree 7 / 8 on [-pi/4, pi/4] rotated by pi/4 (absolute error < 1e-6). branch-free, so that
/// loops over lanes vectorise.
inline void SinCos2Pi(float u, float* s, float* c) {
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

/// SinCos2Pi for every lane.
inline void SinCos2Pi(const Lanes& u, Lanes* s, Lanes* c) {
  for (int k = 0; k < kLanes; ++k) SinCos2Pi(u[k], &(*s)[k], &(*c)[k]);
}

}  // namespace penumbra
