#pragma once
// structure-of-arrays math for shading kLanes points at once (the realtime tier shades a row
// of 16 pixels together, matching Embree's 16-wide ray packets). Eigen's fixed-size arrays
// compile to SIMD instructions; masks are arrays of bool and every lane computes every branch.
//
// SinCos2Pi is shared by the scalar and the lane code, so both sample the same directions.

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <cstring>

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

// masked selects. Eigen 3.4 evaluates select() one lane at a time and GCC does not vectorise a
// per-lane `m ? a : 0` loop, so these use GCC/Clang vector extensions on 4-float chunks (the
// width of SSE2 and NEON registers): compare, then bitwise and with the all-ones / all-zeros
// lane mask. the unselected lanes are +0 even where a is inf or NaN.
#if defined(__GNUC__)
namespace lanes_detail {
typedef float Float4 __attribute__((vector_size(16)));
typedef int32_t Int4 __attribute__((vector_size(16)));
static_assert(kLanes % 4 == 0, "lanes come in 4-float chunks");
static_assert(sizeof(bool) == 1, "LaneMask holds one byte per lane");
static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "MaskOf4 reads bools as a word");

inline Float4 Load4(const Lanes& a, int k) {
  Float4 v;
  std::memcpy(&v, a.data() + k, sizeof v);
  return v;
}
inline void Store4(Int4 bits, Lanes* out, int k) {
  std::memcpy(out->data() + k, &bits, sizeof bits);
}
// all-ones lanes where the bools m[k .. k + 3] are true: their four bytes as one
// little-endian word, tested byte by byte.
inline Int4 MaskOf4(const LaneMask& m, int k) {
  int32_t w;
  std::memcpy(&w, m.data() + k, sizeof w);
  const Int4 bytes = {0xff, 0xff00, 0xff0000, static_cast<int32_t>(0xff000000u)};
  return (Int4{w, w, w, w} & bytes) != 0;
}
inline Int4 Bits4(Float4 v) {
  Int4 r;
  std::memcpy(&r, &v, sizeof r);
  return r;
}
}  // namespace lanes_detail

/// a where c > 0, +0 elsewhere (also where c is NaN), per lane.
__attribute__((always_inline)) inline Lanes WherePositive(const Lanes& c, const Lanes& a) {
  using namespace lanes_detail;
  Lanes out;
  for (int k = 0; k < kLanes; k += 4) Store4(Bits4(Load4(a, k)) & (Load4(c, k) > 0.0f), &out, k);
  return out;
}

/// a where all of c0, c1, c2 are > 0, +0 elsewhere, per lane.
__attribute__((always_inline)) inline Lanes WhereAllPositive(const Lanes& c0, const Lanes& c1,
                                                             const Lanes& c2, const Lanes& a) {
  using namespace lanes_detail;
  Lanes out;
  for (int k = 0; k < kLanes; k += 4)
    Store4(
        Bits4(Load4(a, k)) & (Load4(c0, k) > 0.0f) & (Load4(c1, k) > 0.0f) & (Load4(c2, k) > 0.0f),
        &out, k);
  return out;
}

/// a where m, +0 elsewhere, per lane.
__attribute__((always_inline)) inline Lanes Where(const LaneMask& m, const Lanes& a) {
  using namespace lanes_detail;
  Lanes out;
  for (int k = 0; k < kLanes; k += 4) Store4(Bits4(Load4(a, k)) & MaskOf4(m, k), &out, k);
  return out;
}

/// v where m, +0 elsewhere, per lane.
__attribute__((always_inline)) inline Vec3Lanes Where(const LaneMask& m, const Vec3Lanes& v) {
  using namespace lanes_detail;
  Vec3Lanes out;
  for (int k = 0; k < kLanes; k += 4) {
    const Int4 mask = MaskOf4(m, k);
    Store4(Bits4(Load4(v.x, k)) & mask, &out.x, k);
    Store4(Bits4(Load4(v.y, k)) & mask, &out.y, k);
    Store4(Bits4(Load4(v.z, k)) & mask, &out.z, k);
  }
  return out;
}
#else
inline Lanes WherePositive(const Lanes& c, const Lanes& a) {
  Lanes out;
  for (int k = 0; k < kLanes; ++k) out[k] = c[k] > 0.0f ? a[k] : 0.0f;
  return out;
}
inline Lanes WhereAllPositive(const Lanes& c0, const Lanes& c1, const Lanes& c2, const Lanes& a) {
  Lanes out;
  for (int k = 0; k < kLanes; ++k)
    out[k] = (c0[k] > 0.0f && c1[k] > 0.0f && c2[k] > 0.0f) ? a[k] : 0.0f;
  return out;
}
inline Lanes Where(const LaneMask& m, const Lanes& a) {
  Lanes out;
  for (int k = 0; k < kLanes; ++k) out[k] = m[k] ? a[k] : 0.0f;
  return out;
}
inline Vec3Lanes Where(const LaneMask& m, const Vec3Lanes& v) {
  return {Where(m, v.x), Where(m, v.y), Where(m, v.z)};
}
#endif

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
