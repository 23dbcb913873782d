#pragma once
// particle streaks (render/particle_streaks.h) written once for the CPU backend and the CUDA
// backend's kernels: the ray-capsule test (the realtime tier's per-pixel splat and the
// pathtraced tier's streak BVH on the GPU), the capsule's normal at a hit, a streak's radiance
// (ParticleStreaks::Shade) and the realtime tier's compositing of a streak over what lies behind
// it. plain data only (Float3, LightPod, SkyVolumePod): no Eigen.

#include <cmath>
#include <cstdint>

#include "penumbra/core/host_device.h"
#include "penumbra/render/bsdf_math.h"
#include "penumbra/render/light_math.h"
#include "penumbra/render/media_realtime_math.h"
#include "penumbra/render/shading_math.h"
#include "penumbra/render/sky_eval_math.h"

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

/// the CapsuleOrigin of origin o (world, m) and the capsule around [a, b] of radius r (m), dot
/// products summed as Eigen's (EigenDot).
PB_HOST_DEVICE inline CapsuleOrigin MakeCapsuleOrigin(const Float3& o, const Float3& a,
                                                      const Float3& b, float r) {
  CapsuleOrigin c;
  c.ba = b - a;
  c.oa = o - a;
  c.ob = o - b;
  c.baba = EigenDot(c.ba, c.ba);
  c.baoa = EigenDot(c.ba, c.oa);
  const float oaoa = EigenDot(c.oa, c.oa);
  c.qc = c.baba * oaoa - c.baoa * c.baoa - r * r * c.baba;
  c.sc_a = EigenDot(c.oa, c.oa) - r * r;
  c.sc_b = EigenDot(c.ob, c.ob) - r * r;
  return c;
}

/// nearest t > 0 (m) where the ray o + t d (d unit, o that of `c`) meets the capsule, or -1
/// (Quilez, "Capsule - intersection", 2014: the infinite cylinder, then the nearer end sphere).
/// a ray that starts inside the capsule misses it.
PB_HOST_DEVICE inline float IntersectCapsule(const CapsuleOrigin& c, const Float3& d) {
  const float bard = EigenDot(c.ba, d), rdoa = EigenDot(d, c.oa);
  const float qa = c.baba - bard * bard;
  const float qb = c.baba * rdoa - c.baoa * bard;
  float h = qb * qb - qa * c.qc;
  float y;
  if (qa > 1e-12f) {
    if (h < 0) return -1.0f;  // misses the infinite cylinder, so the capsule too
    const float t = (-qb - sqrtf(h)) / qa;
    y = c.baoa + t * bard;
    if (y > 0 && y < c.baba) return t > 0 ? t : -1.0f;
  } else {
    y = bard > 0 ? -1.0f : c.baba + 1.0f;  // along the axis: the nearer end
  }
  const bool at_a = y <= 0;
  const float sb = EigenDot(d, at_a ? c.oa : c.ob), sc = at_a ? c.sc_a : c.sc_b;
  h = sb * sb - sc;
  if (h <= 0) return -1.0f;
  const float t = -sb - sqrtf(h);
  return t > 0 ? t : -1.0f;
}

/// the unit normal at point p (world) on the capsule around [a, b], facing the ray of
/// direction d (any length): p minus its nearest point on the axis, normalised (-d normalised
/// where p lies on the axis), flipped towards the ray's origin; Eigen's operation order.
PB_HOST_DEVICE inline Float3 CapsuleNormal(const Float3& p, const Float3& a, const Float3& b,
                                           const Float3& d) {
  const Float3 ba = b - a;
  const float l2 = EigenDot(ba, ba);
  // std::clamp(x / std::max(l2, 1e-20f), 0, 1)
  const float x = EigenDot(p - a, ba) / (l2 < 1e-20f ? 1e-20f : l2);
  const float w = x < 0.0f ? 0.0f : (1.0f < x ? 1.0f : x);
  const Float3 q{a.x + w * ba.x, a.y + w * ba.y, a.z + w * ba.z};
  Float3 n = p - q;
  const float nn = sqrtf(EigenDot(n, n));
  if (nn > 0) {
    n = Float3{n.x / nn, n.y / nn, n.z / nn};
  } else {
    // -(d normalised), as Eigen's normalized(): unchanged where its squared norm is 0
    const float z = EigenDot(d, d);
    const float s = z > 0 ? sqrtf(z) : 1.0f;
    n = z > 0 ? Float3{-(d.x / s), -(d.y / s), -(d.z / s)} : Float3{-d.x, -d.y, -d.z};
  }
  if (EigenDot(n, d) > 0) n = Float3{-n.x, -n.y, -n.z};
  return n;
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
