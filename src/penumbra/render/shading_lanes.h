#pragma once
// structure-of-arrays math for shading kLanes points at once (the realtime tier shades a row
// of 16 pixels together, matching Embree's 16-wide ray packets). Eigen's fixed-size arrays
// compile to SIMD instructions; masks are bit sets (one bit per lane, as AVX-512 mask
// registers) made by the lane comparisons below, and every lane computes every branch.
//
// SinCos2Pi is shared by the scalar and the lane code, so both sample the same directions.

#include <Eigen/Core>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "penumbra/render/shading_math.h"
#if defined(__SSE2__)
#include <immintrin.h>
#endif

namespace penumbra {

/// lanes per shading batch (= Embree packet width used by the renderer).
constexpr int kLanes = 16;

/// one float per lane.
using Lanes = Eigen::Array<float, kLanes, 1>;
/// one bool per lane, stored as bit k of a word.
class LaneMask {
 public:
  /// every lane false.
  constexpr LaneMask() = default;
  /// lane k = bit k of `bits` (bits above kLanes are dropped).
  constexpr explicit LaneMask(uint32_t bits) : bits_(bits & kAll) {}
  /// every lane `b`.
  static constexpr LaneMask Constant(bool b) { return LaneMask(b ? kAll : 0u); }

  /// lane k.
  constexpr bool operator[](int k) const { return ((bits_ >> k) & 1u) != 0; }
  /// a writable lane k: `mask[k] = b`.
  class LaneRef {
   public:
    constexpr LaneRef(uint32_t* bits, int k) : bits_(bits), k_(k) {}
    constexpr LaneRef& operator=(bool b) {
      *bits_ = (*bits_ & ~(1u << k_)) | (static_cast<uint32_t>(b) << k_);
      return *this;
    }
    constexpr operator bool() const { return ((*bits_ >> k_) & 1u) != 0; }

   private:
    uint32_t* bits_;
    int k_;
  };
  constexpr LaneRef operator[](int k) { return LaneRef(&bits_, k); }

  constexpr bool any() const { return bits_ != 0; }
  constexpr bool all() const { return bits_ == kAll; }
  /// number of true lanes.
  constexpr int count() const { return std::popcount(bits_); }
  /// bit k = lane k.
  constexpr uint32_t bits() const { return bits_; }

  friend constexpr LaneMask operator&&(LaneMask a, LaneMask b) {
    return LaneMask(a.bits_ & b.bits_);
  }
  friend constexpr LaneMask operator||(LaneMask a, LaneMask b) {
    return LaneMask(a.bits_ | b.bits_);
  }
  constexpr LaneMask operator!() const { return LaneMask(~bits_); }
  friend constexpr bool operator==(LaneMask a, LaneMask b) { return a.bits_ == b.bits_; }

 private:
  static_assert(kLanes <= 32, "a LaneMask holds at most 32 lanes");
  static constexpr uint32_t kAll = kLanes == 32 ? ~0u : (1u << kLanes) - 1u;
  uint32_t bits_ = 0;
};

// lane comparisons. ordered: a lane holding NaN compares false, as the scalar operators.
namespace lanes_detail {
enum class Cmp { kGt, kGe };
template <Cmp kCmp>
inline LaneMask Compare(const Lanes& a, const Lanes& b) {
#if defined(__AVX512F__)
  static_assert(kLanes == 16, "one AVX-512 register of lanes");
  constexpr int kPred = kCmp == Cmp::kGt ? _CMP_GT_OQ : _CMP_GE_OQ;
  return LaneMask(_mm512_cmp_ps_mask(_mm512_loadu_ps(a.data()), _mm512_loadu_ps(b.data()), kPred));
#elif defined(__SSE2__)
  static_assert(kLanes % 4 == 0, "lanes come in 4-float chunks");
  uint32_t bits = 0;
  for (int k = 0; k < kLanes; k += 4) {
    const __m128 x = _mm_loadu_ps(a.data() + k), y = _mm_loadu_ps(b.data() + k);
    const __m128 c = kCmp == Cmp::kGt ? _mm_cmpgt_ps(x, y) : _mm_cmpge_ps(x, y);
    bits |= static_cast<uint32_t>(_mm_movemask_ps(c)) << k;
  }
  return LaneMask(bits);
#else
  uint32_t bits = 0;
  for (int k = 0; k < kLanes; ++k)
    bits |= static_cast<uint32_t>(kCmp == Cmp::kGt ? a[k] > b[k] : a[k] >= b[k]) << k;
  return LaneMask(bits);
#endif
}
}  // namespace lanes_detail

/// a > b per lane.
inline LaneMask GreaterThan(const Lanes& a, const Lanes& b) {
  return lanes_detail::Compare<lanes_detail::Cmp::kGt>(a, b);
}
/// a > b per lane.
inline LaneMask GreaterThan(const Lanes& a, float b) { return GreaterThan(a, Lanes::Constant(b)); }
/// a >= b per lane.
inline LaneMask GreaterEqual(const Lanes& a, const Lanes& b) {
  return lanes_detail::Compare<lanes_detail::Cmp::kGe>(a, b);
}

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

inline Float4 Load4(const Lanes& a, int k) {
  Float4 v;
  std::memcpy(&v, a.data() + k, sizeof v);
  return v;
}
inline void Store4(Int4 bits, Lanes* out, int k) {
  std::memcpy(out->data() + k, &bits, sizeof bits);
}
// all-ones lanes where the lanes k .. k + 3 of m are true.
inline Int4 MaskOf4(const LaneMask& m, int k) {
  const int32_t w = static_cast<int32_t>(m.bits() >> k);
  return (Int4{w, w, w, w} & Int4{1, 2, 4, 8}) != 0;
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
#if defined(__AVX512F__)
  _mm512_storeu_ps(out.data(), _mm512_maskz_mov_ps(m.bits(), _mm512_loadu_ps(a.data())));
#else
  for (int k = 0; k < kLanes; k += 4) Store4(Bits4(Load4(a, k)) & MaskOf4(m, k), &out, k);
#endif
  return out;
}

/// v where m, +0 elsewhere, per lane.
__attribute__((always_inline)) inline Vec3Lanes Where(const LaneMask& m, const Vec3Lanes& v) {
  return {Where(m, v.x), Where(m, v.y), Where(m, v.z)};
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

namespace pbm {
/// SinCos2Pi for every lane.
inline void SinCos2Pi(const Lanes& u, Lanes* s, Lanes* c) {
  for (int k = 0; k < kLanes; ++k) SinCos2Pi(u[k], &(*s)[k], &(*c)[k]);
}
}  // namespace pbm

/// sin(2 pi u) and cos(2 pi u) for u in [0, 1) (the shared formula, render/shading_math.h),
/// for a float or every lane.
using pbm::SinCos2Pi;

// the Lanes overloads of the shared formulas' helpers (render/shading_math.h): the same names,
// so that one template body serves float and Lanes.
namespace pbm {
inline Lanes Min(const Lanes& a, float b) { return a.min(b); }
inline Lanes Min(const Lanes& a, const Lanes& b) { return a.min(b); }
inline Lanes Max(const Lanes& a, float b) { return a.max(b); }
inline Lanes Max(const Lanes& a, const Lanes& b) { return a.max(b); }
/// x.max(lo).min(hi): std::clamp lane by lane for x not NaN.
inline Lanes Clamp(const Lanes& x, float lo, float hi) { return x.max(lo).min(hi); }
inline Lanes Sqrt(const Lanes& x) { return x.sqrt(); }
/// Eigen's vectorised exp (within 2 ulp of the exact value).
inline Lanes Exp(const Lanes& x) { return x.exp(); }
inline Lanes WhereAllPositive(const Lanes& c0, const Lanes& c1, const Lanes& c2, const Lanes& a) {
  return penumbra::WhereAllPositive(c0, c1, c2, a);
}
inline Lanes StepGreaterEqual(const Lanes& x, float e) {
  Lanes s;
  for (int k = 0; k < kLanes; ++k) s[k] = x[k] >= e ? 1.0f : 0.0f;
  return s;
}
inline LaneMask GreaterThan(const Lanes& a, float b) { return penumbra::GreaterThan(a, b); }
inline LaneMask GreaterThan(const Lanes& a, const Lanes& b) { return penumbra::GreaterThan(a, b); }
inline LaneMask GreaterEqual(const Lanes& a, const Lanes& b) {
  return penumbra::GreaterEqual(a, b);
}
inline Lanes StepGreaterThan(const Lanes& x, float e) {
  return (x > e).select(Lanes::Ones(), Lanes::Zero());
}
inline Lanes WherePositiveElse(const Lanes& c, const Lanes& a, float b) {
  return (c > 0.0f).select(a, b);
}
inline Lanes Where(const LaneMask& m, const Lanes& a) { return penumbra::Where(m, a); }
inline float& LaneOf(Lanes& x, int k) { return x[k]; }
inline float LaneOf(const Lanes& x, int k) { return x[k]; }
template <typename F>
inline void ForEachLane(const LaneMask& m, F&& fn) {
  for (uint32_t bits = m.bits(); bits != 0; bits &= bits - 1) fn(std::countr_zero(bits));
}
template <>
inline Lanes Splat<Lanes>(float x) {
  return Lanes::Constant(x);
}
inline Lanes SignNonNegative(const Lanes& x) {
  Lanes s;
  for (int k = 0; k < kLanes; ++k) s[k] = x[k] >= 0 ? 1.0f : -1.0f;
  return s;
}
}  // namespace pbm

}  // namespace penumbra
