#pragma once
// particle streaks (render/particles/particle_streaks.h) written once for the CPU backend and the
// CUDA backend's kernels: the ray-capsule test (the realtime tier's per-pixel splat and the
// pathtraced tier's streak BVH on the GPU), the capsule's normal at a hit, a streak's radiance
// (ParticleStreaks::Shade) and the realtime tier's compositing of a streak over what lies behind
// it. plain data only (Float3, LightPod, SkyVolumePod): no Eigen.

#include <cmath>
#include <cstdint>
#include <cstring>

#include "penumbra/core/host_device.h"
#include "penumbra/render/light/bsdf_math.h"
#include "penumbra/render/light/light_math.h"
#include "penumbra/render/media/media_realtime_math.h"
#include "penumbra/render/shading_math.h"
#include "penumbra/render/sky/sky_eval_math.h"

namespace penumbra {

/// one channel of a streak of coverage `alpha` in (0, 1] and radiance `Lp` (cd/m^2) drawn over
/// the radiance `L` behind it: alpha Lp + (1 - alpha) L (Porter and Duff's "over", "Compositing
/// digital images", SIGGRAPH 1984).
PB_HOST_DEVICE inline float StreakOver(float alpha, float Lp, float L) {
  return alpha * Lp + (1.0f - alpha) * L;
}

/// what the ray-capsule test needs of a capsule around [a, b] of radius r and a ray origin o
/// that does not depend on the ray's direction (rays that share o share it): b - a, o - a,
/// o - b and the dot products of Quilez's test (MakeCapsuleOrigin).
struct CapsuleOrigin {
  Float3 ba, oa, ob;
  float baba = 0, baoa = 0, qc = 0, sc_a = 0, sc_b = 0;
};

/// a . b summed as Eigen sums it (EigenDot: x + (y + z)), every product and sum rounded on its
/// own on both processors (MulRn, AddRn: no fused multiply-add on the device), so that the
/// ray-capsule test below gives the CPU's bits on the GPU.
PB_HOST_DEVICE inline float EigenDotRn(const Float3& a, const Float3& b) {
  return AddRn(MulRn(a.x, b.x), AddRn(MulRn(a.y, b.y), MulRn(a.z, b.z)));
}

/// the CapsuleOrigin of origin o (world, m) and the capsule around [a, b] of radius r (m), dot
/// products summed as Eigen's (EigenDotRn); each operation rounded on its own (the CPU's bits
/// on the GPU too).
PB_HOST_DEVICE inline CapsuleOrigin MakeCapsuleOrigin(const Float3& o, const Float3& a,
                                                      const Float3& b, float r) {
  CapsuleOrigin c;
  c.ba = b - a;
  c.oa = o - a;
  c.ob = o - b;
  c.baba = EigenDotRn(c.ba, c.ba);
  c.baoa = EigenDotRn(c.ba, c.oa);
  const float oaoa = EigenDotRn(c.oa, c.oa);
  const float rr = MulRn(r, r);
  c.qc = SubRn(SubRn(MulRn(c.baba, oaoa), MulRn(c.baoa, c.baoa)), MulRn(rr, c.baba));
  c.sc_a = SubRn(EigenDotRn(c.oa, c.oa), rr);
  c.sc_b = SubRn(EigenDotRn(c.ob, c.ob), rr);
  return c;
}

/// nearest t > 0 (m) where the ray o + t d (d unit, o that of `c`) meets the capsule, or -1
/// (Quilez, "Capsule - intersection", 2014: the infinite cylinder, then the nearer end sphere).
/// a ray that starts inside the capsule misses it. each operation rounded on its own (MulRn,
/// AddRn, SubRn): the test is ill-conditioned for thin capsules far away (the discriminant is a
/// difference of nearly equal products), so a fused multiply-add would move the edge of a
/// widened streak by a good part of its radius; this way the GPU gives the CPU's bits.
PB_HOST_DEVICE inline float IntersectCapsule(const CapsuleOrigin& c, const Float3& d) {
  const float bard = EigenDotRn(c.ba, d), rdoa = EigenDotRn(d, c.oa);
  const float qa = SubRn(c.baba, MulRn(bard, bard));
  const float qb = SubRn(MulRn(c.baba, rdoa), MulRn(c.baoa, bard));
  float h = SubRn(MulRn(qb, qb), MulRn(qa, c.qc));
  float y;
  if (qa > 1e-12f) {
    if (h < 0) return -1.0f;  // misses the infinite cylinder, so the capsule too
    const float t = (-qb - sqrtf(h)) / qa;
    y = AddRn(c.baoa, MulRn(t, bard));
    if (y > 0 && y < c.baba) return t > 0 ? t : -1.0f;
  } else {
    y = bard > 0 ? -1.0f : c.baba + 1.0f;  // along the axis: the nearer end
  }
  const bool at_a = y <= 0;
  const float sb = EigenDotRn(d, at_a ? c.oa : c.ob), sc = at_a ? c.sc_a : c.sc_b;
  h = SubRn(MulRn(sb, sb), sc);
  if (h <= 0) return -1.0f;
  const float t = -sb - sqrtf(h);
  return t > 0 ? t : -1.0f;
}

/// the t (in units of |d|: the pixel's depth for a camera ray) where the ray o + t d (d any
/// length, o that of `c`) meets the capsule, or -1: IntersectCapsule along d / |d| (|d| summed
/// as Eigen's norm()), divided by |d|. the realtime splat's pixel test (ParticleStreaks and the
/// CUDA backend's splat kernel).
PB_HOST_DEVICE inline float IntersectCapsuleRay(const CapsuleOrigin& c, const Float3& d) {
  const float len = sqrtf(EigenDotRn(d, d));
  const float t = IntersectCapsule(c, Float3{d.x / len, d.y / len, d.z / len});
  return t > 0 ? t / len : -1.0f;
}

/// the unit normal at point p (world) on the capsule around [a, b], facing the ray of
/// direction d (any length): p minus its nearest point on the axis, normalised (-d normalised
/// where p lies on the axis), flipped towards the ray's origin; Eigen's operation order, each
/// operation rounded on its own (EigenDotRn, MulRn, AddRn: the CPU's bits on the GPU).
PB_HOST_DEVICE inline Float3 CapsuleNormal(const Float3& p, const Float3& a, const Float3& b,
                                           const Float3& d) {
  const Float3 ba = b - a;
  const float l2 = EigenDotRn(ba, ba);
  // std::clamp(x / std::max(l2, 1e-20f), 0, 1)
  const float x = EigenDotRn(p - a, ba) / (l2 < 1e-20f ? 1e-20f : l2);
  const float w = x < 0.0f ? 0.0f : (1.0f < x ? 1.0f : x);
  const Float3 q{AddRn(a.x, MulRn(w, ba.x)), AddRn(a.y, MulRn(w, ba.y)),
                 AddRn(a.z, MulRn(w, ba.z))};
  Float3 n = p - q;
  const float nn = sqrtf(EigenDotRn(n, n));
  if (nn > 0) {
    n = Float3{n.x / nn, n.y / nn, n.z / nn};
  } else {
    // -(d normalised), as Eigen's normalized(): unchanged where its squared norm is 0
    const float z = EigenDotRn(d, d);
    const float s = z > 0 ? sqrtf(z) : 1.0f;
    n = z > 0 ? Float3{-(d.x / s), -(d.y / s), -(d.z / s)} : Float3{-d.x, -d.y, -d.z};
  }
  if (EigenDotRn(n, d) > 0) n = Float3{-n.x, -n.y, -n.z};
  return n;
}

/// near plane (m, optical-frame depth) of the realtime tier's streak splat: drops wholly in
/// front of it are not drawn, and a streak's segment is clipped to kStreakNear + r.
constexpr float kStreakNear = 0.01f;

/// a streak as the realtime tier's splat sees it: the pixel box [u0, u1] x [v0, v1] whose
/// pixel-centre rays are tested against its capsule (empty: u0 > u1 or v0 > v1) and its
/// projected segment (ua, va) - (ub, vb) (px) with the capsule's projected radius rp (px, one
/// pixel of margin included).
struct StreakProjection {
  int u0 = 0, u1 = -1, v0 = 0, v1 = -1;
  float ua = 0, va = 0, ub = 0, vb = 0, rp = 0;
  /// the depth (m) rp is taken at: the clipped segment's nearest end depth minus r, at least
  /// kStreakNear (StreakMotionMarginPx).
  float z_near = 0;
  PB_HOST_DEVICE bool empty() const { return u0 > u1 || v0 > v1; }
};

/// world point p (m) in a camera's optical frame: R_OW p + p_OW (R_OW row-major), each row's
/// dot product summed as Eigen's Matrix3f * Vector3f sums it (EigenDotRn), then the offset;
/// each operation rounded on its own (the CPU's bits on the GPU).
PB_HOST_DEVICE inline Float3 StreakToOptical(const float R_OW[9], const Float3& p_OW,
                                             const Float3& p) {
  return Float3{AddRn(EigenDotRn(Float3{R_OW[0], R_OW[1], R_OW[2]}, p), p_OW.x),
                AddRn(EigenDotRn(Float3{R_OW[3], R_OW[4], R_OW[5]}, p), p_OW.y),
                AddRn(EigenDotRn(Float3{R_OW[6], R_OW[7], R_OW[8]}, p), p_OW.z)};
}

/// the realtime splat's projection of the capsule around [ao, bo] (optical frame, m; z
/// forward) of radius r (m) into a W x H image of pinhole intrinsics fx, fy, cx, cy (px, as
/// CameraIntrinsics): the segment clipped to z >= kStreakNear + r (empty when both ends lie in
/// front of that), both ends projected (in double, then rounded to float), rp = max(fx, fy) r /
/// (nearest z - r) + 1 px, and the box of the projected segment widened by rp, clamped to the
/// image (empty when outside it). lens distortion is ignored: it moves pixels by more than the
/// margin only far from the centre, where a streak may then be clipped. products and sums
/// rounded on their own (the CPU's bits on the GPU: the same pixels tested).
/// (ParticleStreaks::BuildPixelHits and the CUDA backend's splat kernel.)
PB_HOST_DEVICE inline StreakProjection ProjectStreak(Float3 ao, Float3 bo, float r, double fx,
                                                     double fy, double cx, double cy, int W,
                                                     int H) {
  StreakProjection p;
  const float zmin = kStreakNear + r;
  if (ao.z < zmin && bo.z < zmin) return p;
  if (ao.z < zmin) {
    const float s = (bo.z - zmin) / (bo.z - ao.z);
    ao = Float3{AddRn(bo.x, MulRn(ao.x - bo.x, s)), AddRn(bo.y, MulRn(ao.y - bo.y, s)),
                AddRn(bo.z, MulRn(ao.z - bo.z, s))};
  }
  if (bo.z < zmin) {
    const float s = (ao.z - zmin) / (ao.z - bo.z);
    bo = Float3{AddRn(ao.x, MulRn(bo.x - ao.x, s)), AddRn(ao.y, MulRn(bo.y - ao.y, s)),
                AddRn(ao.z, MulRn(bo.z - ao.z, s))};
  }
  const float z_near = (ao.z < bo.z ? ao.z : bo.z) - r;
  const float f_max = static_cast<float>(fx < fy ? fy : fx);
  p.z_near = z_near < kStreakNear ? kStreakNear : z_near;
  p.rp = f_max * r / p.z_near + 1.0f;
  p.ua = static_cast<float>(fx * static_cast<double>(ao.x) / static_cast<double>(ao.z) + cx);
  p.va = static_cast<float>(fy * static_cast<double>(ao.y) / static_cast<double>(ao.z) + cy);
  p.ub = static_cast<float>(fx * static_cast<double>(bo.x) / static_cast<double>(bo.z) + cx);
  p.vb = static_cast<float>(fy * static_cast<double>(bo.y) / static_cast<double>(bo.z) + cy);
  const int u0 = static_cast<int>(floorf((p.ua < p.ub ? p.ua : p.ub) - p.rp));
  const int u1 = static_cast<int>(ceilf((p.ua < p.ub ? p.ub : p.ua) + p.rp));
  const int v0 = static_cast<int>(floorf((p.va < p.vb ? p.va : p.vb) - p.rp));
  const int v1 = static_cast<int>(ceilf((p.va < p.vb ? p.vb : p.va) + p.rp));
  p.u0 = u0 < 0 ? 0 : u0;
  p.u1 = u1 < W - 1 ? u1 : W - 1;
  p.v0 = v0 < 0 ? 0 : v0;
  p.v1 = v1 < H - 1 ? v1 : H - 1;
  return p;
}

/// the columns [*c0, *c1] of row v (within the box of `p`) whose pixel centres lie within rp of
/// the part of the projected segment near that row: the segment's parameters where its v is
/// v -+ rp (the whole segment when it is nearly horizontal), their u -+ rp. (the splat tests
/// only these pixels of the row; empty: *c0 > *c1.)
PB_HOST_DEVICE inline void StreakRowColumns(const StreakProjection& p, int v, int* c0, int* c1) {
  const float du = p.ub - p.ua, dv = p.vb - p.va;
  float s0 = 0, s1 = 1;
  if (fabsf(dv) > 1e-6f) {
    // std::clamp(x, 0, 1)
    const float x0 = (static_cast<float>(v) - p.rp - p.va) / dv;
    const float x1 = (static_cast<float>(v) + p.rp - p.va) / dv;
    s0 = x0 < 0.0f ? 0.0f : (1.0f < x0 ? 1.0f : x0);
    s1 = x1 < 0.0f ? 0.0f : (1.0f < x1 ? 1.0f : x1);
    if (s0 > s1) {
      const float t = s0;
      s0 = s1;
      s1 = t;
    }
  }
  const float e0 = AddRn(p.ua, MulRn(s0, du)), e1 = AddRn(p.ua, MulRn(s1, du));
  const float ul = (e0 < e1 ? e0 : e1) - p.rp;
  const float uh = (e0 < e1 ? e1 : e0) + p.rp;
  const int l = static_cast<int>(floorf(ul)), h = static_cast<int>(ceilf(uh));
  *c0 = p.u0 < l ? l : p.u0;
  *c1 = h < p.u1 ? h : p.u1;
}

/// a moving camera's rows as the realtime splat bounds them (ParticleStreaks' StreakMotionOf
/// makes it from a Camera; zero: a still camera): every row's pose (camera.h: slerped and lerped
/// from X_WO at the row's time) is turned by at most `turn` (rad) from the pose X_WO that
/// ProjectStreak's box is taken in, and its origin lies at most `shift` (m) from X_WO's;
/// `tan_max` is the largest |(x, y)| of a pixel centre's normalised pinhole coordinates ((u -
/// cx) / fx, (v - cy) / fy) over the image.
struct StreakMotion {
  float turn = 0, shift = 0, tan_max = 0;
  PB_HOST_DEVICE bool moving() const { return turn > 0 || shift > 0; }
};

/// how far (px) a pixel centre whose ray, from any row's pose of motion `m`, meets a point p
/// at depth >= z_near (m, in X_WO) can lie from p's projection in X_WO, for lenses of focal
/// lengths up to f_max (px); -1 when the motion is too large to bound (the whole image).
/// derivation: the ray leaves o(a) (|o(a) - o| <= shift) along R(a) d, d the pixel's direction
/// in X_WO, turned from R d by <= turn; seen from o, p's direction differs from the ray's by <=
/// asin(shift / |p - o|) <= asin(shift / z_near) (the angle opposite the shortest side of the
/// triangle o, o(a), p), so from R d by delta <= turn + asin(shift / z_near). on the image
/// plane z = 1 (the gnomonic map) an arc of delta between directions whose polar angles stay
/// below phi moves the point by at most delta / cos^2(phi) = delta (1 + tan^2 phi); the pixel's
/// polar angle is at most atan(tan_max), p's at most that plus delta (a cap below the horizon is
/// convex on the sphere), so |(x, y) - p's| <= delta (1 + tan^2(atan(tan_max) + delta)), times
/// f_max in pixels. asin(s) <= s / sqrt(1 - s^2) and tan(delta) <= delta / (1 - delta^2 / 2)
/// (delta < 1) keep it to square roots; 1 % and 0.01 px to spare for rounding.
PB_HOST_DEVICE inline float StreakMotionMarginPx(const StreakMotion& m, float z_near, float f_max) {
  const float s = m.shift / z_near;
  if (!(s < 0.5f)) return -1.0f;
  const float delta = m.turn + s / sqrtf(1.0f - s * s);
  if (!(delta < 1.0f)) return -1.0f;
  const float tan_delta = delta / (1.0f - 0.5f * delta * delta);
  const float den = 1.0f - m.tan_max * tan_delta;
  if (!(den > 0.05f)) return -1.0f;
  const float tan_phi = (m.tan_max + tan_delta) / den;
  return 1.01f * f_max * delta * (1.0f + tan_phi * tan_phi) + 0.01f;
}

/// ProjectStreak's box p (a streak's projection in X_WO) widened for a moving camera's rows
/// (motion m, StreakMotionMarginPx at p.z_near) so that it holds every pixel centre of a W x H
/// image whose ray, from its own row's pose, meets the capsule at a point of depth >= p.z_near
/// in X_WO (what ProjectStreak's box guarantees for a still camera): rp widened by the margin,
/// the box remade from the segment (a box outside the image may so come into it); the whole
/// image where the motion cannot be bounded. a p of a streak wholly behind X_WO's near plane
/// (z_near 0) stays empty, and a still m leaves p as it is. fx, fy: the intrinsics' focal
/// lengths (px).
PB_HOST_DEVICE inline StreakProjection WidenStreakForMotion(StreakProjection p,
                                                            const StreakMotion& m, double fx,
                                                            double fy, int W, int H) {
  if (!(p.z_near > 0) || !m.moving()) return p;
  const float margin = StreakMotionMarginPx(m, p.z_near, static_cast<float>(fx < fy ? fy : fx));
  if (margin < 0) {
    p.u0 = 0;
    p.u1 = W - 1;
    p.v0 = 0;
    p.v1 = H - 1;
    return p;
  }
  const float rp = p.rp + margin;
  const int u0 = static_cast<int>(floorf((p.ua < p.ub ? p.ua : p.ub) - rp));
  const int u1 = static_cast<int>(ceilf((p.ua < p.ub ? p.ub : p.ua) + rp));
  const int v0 = static_cast<int>(floorf((p.va < p.vb ? p.va : p.vb) - rp));
  const int v1 = static_cast<int>(ceilf((p.va < p.vb ? p.vb : p.va) + rp));
  p.u0 = u0 < 0 ? 0 : u0;
  p.u1 = u1 < W - 1 ? u1 : W - 1;
  p.v0 = v0 < 0 ? 0 : v0;
  p.v1 = v1 < H - 1 ? v1 : H - 1;
  return p;
}

/// a moving camera's row pose `row` (12 doubles: R_WO row-major, then the origin o in world m;
/// Camera::PoseAtRow, as StreakSplatView::rows) as the world-to-optical transform
/// StreakToOptical takes: R_OW = R_WO^T and p_OW = -R_OW o, in double, each product and sum
/// rounded on its own (the CPU's bits on the GPU), then rounded to float.
PB_HOST_DEVICE inline void StreakRowToOptical(const double row[12], float R_OW[9], Float3* p_OW) {
  double p[3];
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) R_OW[3 * i + j] = static_cast<float>(row[3 * j + i]);
    p[i] = -AddRnD(AddRnD(MulRnD(row[i], row[9]), MulRnD(row[3 + i], row[10])),
                   MulRnD(row[6 + i], row[11]));
  }
  *p_OW = Float3{static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2])};
}

/// the columns [*c0, *c1] of row v (empty: *c0 > *c1) that the splat tests for the capsule
/// around [a, b] (world, m) of radius r (m) when row v is seen from its own pose `row`
/// (StreakRowToOptical's layout; a moving camera): ProjectStreak of the ends in that row's
/// optical frame, then StreakRowColumns at v, empty where v lies outside that projection's box.
/// this holds every pixel of row v whose ray meets the capsule as ProjectStreak's box and
/// StreakRowColumns do for a still camera (the row is a still pinhole camera at its pose).
PB_HOST_DEVICE inline void StreakRowColumnsAtPose(const double row[12], const Float3& a,
                                                  const Float3& b, float r, double fx, double fy,
                                                  double cx, double cy, int W, int H, int v,
                                                  int* c0, int* c1) {
  float R_OW[9];
  Float3 p_OW;
  StreakRowToOptical(row, R_OW, &p_OW);
  const StreakProjection q = ProjectStreak(StreakToOptical(R_OW, p_OW, a),
                                           StreakToOptical(R_OW, p_OW, b), r, fx, fy, cx, cy, W, H);
  if (q.empty() || v < q.v0 || v > q.v1) {
    *c0 = 0;
    *c1 = -1;
    return;
  }
  StreakRowColumns(q, v, c0, c1);
}

/// a pixel's StreakKey when no streak meets its ray (larger than every key).
constexpr uint64_t kNoStreakKey = ~uint64_t{0};

/// the nearest streak of a pixel as one 64-bit key: the float bits of its t (> 0, so they sort
/// as unsigned integers) above its index, so that the smallest key is the nearest streak and,
/// at equal t, the lower index (the host splat's rule). an integer minimum does not depend on
/// the order the keys arrive in (the device's atomicMin), so the splat is deterministic.
PB_HOST_DEVICE inline uint64_t StreakKey(float t, int32_t index) {
  uint32_t bits;
  std::memcpy(&bits, &t, sizeof(bits));
  return (static_cast<uint64_t>(bits) << 32) | static_cast<uint32_t>(index);
}
/// the t and index of a StreakKey.
PB_HOST_DEVICE inline float StreakKeyT(uint64_t key) {
  const uint32_t bits = static_cast<uint32_t>(key >> 32);
  float t;
  std::memcpy(&t, &bits, sizeof(t));
  return t;
}
PB_HOST_DEVICE inline int32_t StreakKeyIndex(uint64_t key) {
  return static_cast<int32_t>(static_cast<uint32_t>(key & 0xffffffffu));
}

/// a particle set's kind as the shared shading takes it (ParticleKind's values).
enum class StreakKind : int32_t { kRain = 0, kSnow = 1, kSpark = 2 };

/// a particle set as its streaks are shaded: kind, colour (rain's transmission tint, snow's
/// albedo) and emission (cd/m^2; sparks').
struct StreakSetPod {
  StreakKind kind = StreakKind::kRain;
  Float3 color{1, 1, 1};
  Float3 emission{0, 0, 0};
};

/// ParticleStreaks::Shade: the radiance (cd/m^2) of a streak of set `set` at point p (world,
/// m) with unit normal ng (facing the viewer): a spark's emission; a rain streak's precomputed
/// radiance `*rain` where given (ParticleStreaks::PrecomputeRain); else colour x (sky + E) +
/// emission with E the sum over the num_lights lights of their sample at p with (u1, u2) =
/// (0.5, 0.5) (SampleLight, LightSampler::Sample's form; unshadowed), times max(0, ng . wi) / pi
/// for snow and 1 / (4 pi) for rain, and sky the occluded sphere-average sky radiance at p
/// (SkyVolumeAmbientRadiance over `volume`; `sky_ambient`, the open sky's, where the volume is
/// empty or p lies outside it).
PB_HOST_DEVICE inline Float3 ShadeStreak(const StreakSetPod& set, const Float3* rain,
                                         const Float3& p, const Float3& ng, const LightPod* lights,
                                         int num_lights, const SkyVolumePod& volume,
                                         const Float3& sky_ambient) {
  if (set.kind == StreakKind::kSpark) return set.emission;
  if (set.kind == StreakKind::kRain && rain != nullptr) return *rain;
  Float3 E{0, 0, 0};
  for (int j = 0; j < num_lights; ++j) {
    Float3 wi, Ej;
    float distance = 0;
    bool valid = false;
    SampleLight<float, Float3, bool, true>(lights[j], p, 0.5f, 0.5f, &wi, &distance, &Ej, &valid);
    if (!valid) continue;
    float s;
    if (set.kind == StreakKind::kSnow) {
      const float c = EigenDot(ng, wi);
      s = (0.0f < c ? c : 0.0f) * 0.318309886f;  // std::max(0.0f, c) / pi
    } else {
      s = kInv4Pi;
    }
    E = Float3{E.x + Ej.x * s, E.y + Ej.y * s, E.z + Ej.z * s};
  }
  float sky[3];
  const float p3[3] = {p.x, p.y, p.z}, open[3] = {sky_ambient.x, sky_ambient.y, sky_ambient.z};
  SkyVolumeAmbientRadiance(volume, p3, open, sky);
  return Float3{set.color.x * (sky[0] + E.x) + set.emission.x,
                set.color.y * (sky[1] + E.y) + set.emission.y,
                set.color.z * (sky[2] + E.z) + set.emission.z};
}

}  // namespace penumbra
