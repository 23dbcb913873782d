#pragma once
// the realtime tier's particle streaks (rain, snow, sparks): splatted per pixel by the frame
// (SplatStreakRow, ShadeSplatPixel over render/particles/particle_math.h's projection and capsule
// test, as the CPU's ParticleStreaks::BuildPixelHits), a pixel's found by PixelStreakOf and drawn
// over its radiance by ApplyStreak (scene_view.h).

#include <cstdint>

#include "penumbra/core/host_device.h"
#include "penumbra/render/particles/particle_math.h"
#include "penumbra/render/transport/realtime_shading.h"
#include "penumbra/render/transport/scene_view.h"

namespace penumbra::cuda {

/// the projection of splat streak s (ProjectStreak of its ends in the frame's optical frame,
/// StreakToOptical), its box widened by a moving camera's rows (WidenStreakForMotion; nothing
/// for a still camera).
PB_HOST_DEVICE inline StreakProjection SplatProjection(const RealtimeFrameView& f,
                                                       const StreakPod& s) {
  const StreakSplatView& sp = f.splat;
  const Float3 ao = StreakToOptical(sp.R_OW, sp.p_OW, Float3{s.a[0], s.a[1], s.a[2]});
  const Float3 bo = StreakToOptical(sp.R_OW, sp.p_OW, Float3{s.b[0], s.b[1], s.b[2]});
  const int W = f.camera.width, H = f.camera.height;
  const StreakProjection p = ProjectStreak(ao, bo, s.r, sp.fx, sp.fy, sp.cx, sp.cy, W, H);
  return sp.poses != nullptr ? WidenStreakForMotion(p, sp.motion, sp.fx, sp.fy, W, H) : p;
}

/// the ray of pixel (u, v) that the splat tests and shades (origin and direction as the CPU's
/// Camera::GenerateRay, which ParticleStreaks' host splat traces): with f.splat.rows (a moving
/// camera without lens distortion) the row's double pose times the pixel's double coordinates
/// ((u - cx) / fx, (v - cy) / fy, 1), each product and sum rounded on its own (MulRnD, AddRnD:
/// Eigen's order), then rounded to float, and the row's origin; else PrimaryRay<true>.
PB_HOST_DEVICE inline TraceRay SplatRay(const RealtimeFrameView& f, int u, int v) {
  if (f.splat.rows == nullptr) return PrimaryRay<true>(f.camera, u, v);
  const StreakSplatView& sp = f.splat;
  const double* r = sp.rows + 12 * static_cast<int64_t>(v);
  const double x = (static_cast<double>(u) - sp.cx) / sp.fx;
  const double y = (static_cast<double>(v) - sp.cy) / sp.fy;
  float d[3];
  for (int i = 0; i < 3; ++i)
    d[i] = static_cast<float>(
        AddRnD(AddRnD(MulRnD(r[3 * i], x), MulRnD(r[3 * i + 1], y)), MulRnD(r[3 * i + 2], 1.0)));
  TraceRay ray;
  ray.o = F3{static_cast<float>(r[9]), static_cast<float>(r[10]), static_cast<float>(r[11])};
  ray.d = F3{d[0], d[1], d[2]};
  ray.tmin = f.camera.near;
  ray.tmax = INFINITY;
  return ray;
}

/// keeps the smaller of *slot and key: atomicMin on the device (the keys of many streaks meet
/// there; an integer minimum, so the result does not depend on their order), a plain minimum
/// on the host (RenderRealtimeOnHost splats one streak at a time).
PB_HOST_DEVICE inline void KeepNearestStreak(unsigned long long* slot, unsigned long long key) {
#if defined(__CUDA_ARCH__)
  atomicMin(slot, key);
#else
  if (key < *slot) *slot = key;
#endif
}

/// the number of streaks the splat of f.splat draws: *count where the count is in the
/// reader's memory (the device culling's streaks in place: streaks.num only a bound), else
/// streaks.num.
PB_HOST_DEVICE inline int32_t SplatStreakCount(const StreakSplatView& sp) {
  return sp.count != nullptr ? *sp.count : sp.streaks.num;
}

/// splat streak k (projection p, SplatProjection) on row v (inside p's box): every pixel of
/// StreakRowColumns (a moving camera, f.splat.poses: StreakRowColumnsAtPose, the columns in the
/// row's own pose) whose pixel-centre ray (SplatRay) meets the capsule (IntersectCapsuleRay,
/// with the row's ray origin) keeps StreakKey(t, k) in f.splat.nearest if it is smaller, as
/// ParticleStreaks::BuildPixelHits for the CPU's pixel rays: every product and sum of the rays,
/// the projection and the capsule test rounded on its own (SplatRay, MulRn, AddRn), so
/// the device finds the CPU's pixels and t to the bit.
PB_HOST_DEVICE inline void SplatStreakRow(const RealtimeFrameView& f, int k,
                                          const StreakProjection& p, int v) {
  const StreakSplatView& sp = f.splat;
  const StreakPod& s = sp.streaks.streaks[k];
  int c0, c1;
  if (sp.poses != nullptr)
    StreakRowColumnsAtPose(sp.poses + 12 * static_cast<int64_t>(v), Float3{s.a[0], s.a[1], s.a[2]},
                           Float3{s.b[0], s.b[1], s.b[2]}, s.r, sp.fx, sp.fy, sp.cx, sp.cy,
                           f.camera.width, f.camera.height, v, &c0, &c1);
  else
    StreakRowColumns(p, v, &c0, &c1);
  if (c0 > c1) return;
  const CapsuleOrigin c =
      MakeCapsuleOrigin(ToFloat3(SplatRay(f, c0, v).o), Float3{s.a[0], s.a[1], s.a[2]},
                        Float3{s.b[0], s.b[1], s.b[2]}, s.r);
  for (int u = c0; u <= c1; ++u) {
    const float t = IntersectCapsuleRay(c, ToFloat3(SplatRay(f, u, v).d));
    if (!(t > 0)) continue;
    KeepNearestStreak(&f.splat.nearest[static_cast<int64_t>(v) * f.camera.width + u],
                      static_cast<unsigned long long>(StreakKey(t, k)));
  }
}

/// pixel (u, v)'s streak after the splat, shaded into f.splat.pixels where it has one, as the
/// host splat shades it (RealtimeFrameData's host path: ParticleStreaks::PixelHit and Shade):
/// ShadeStreak of the streak's set at the pixel ray's hit o + t |d| d / |d| with the capsule's
/// normal at o + t d (CapsuleNormal), the frame's lights and its sky volume over the open sky's
/// radiance; rain at the streak's centre (ParticleStreaks::PrecomputeRain's point; its normal
/// unused). t is the primary ray's (the depth's units), alpha the streak's coverage.
PB_HOST_DEVICE inline void ShadeSplatPixel(const RealtimeFrameView& f, int u, int v) {
  const int64_t i = static_cast<int64_t>(v) * f.camera.width + u;
  const unsigned long long key = f.splat.nearest[i];
  if (key == kNoStreakKey) return;
  const float t = StreakKeyT(key);
  const StreakPod& s = f.splat.streaks.streaks[StreakKeyIndex(key)];
  const StreakSetPod& set = f.splat.streaks.sets[s.set];
  const Float3 a{s.a[0], s.a[1], s.a[2]}, b{s.b[0], s.b[1], s.b[2]};
  const TraceRay r = SplatRay(f, u, v);
  const Float3 o = ToFloat3(r.o), d = ToFloat3(r.d);
  Float3 p, ng{0, 0, 1};
  if (set.kind == StreakKind::kRain) {
    p = Float3{0.5f * (a.x + b.x), 0.5f * (a.y + b.y), 0.5f * (a.z + b.z)};
  } else {
    // the hit point and normal rounded as the CPU rounds them (AddRn, MulRn, EigenDotRn)
    ng = CapsuleNormal(
        Float3{AddRn(o.x, MulRn(t, d.x)), AddRn(o.y, MulRn(t, d.y)), AddRn(o.z, MulRn(t, d.z))}, a,
        b, d);
    const float d_len = sqrtf(EigenDotRn(d, d));
    const float td = t * d_len;
    p = Float3{AddRn(o.x, MulRn(td, d.x / d_len)), AddRn(o.y, MulRn(td, d.y / d_len)),
               AddRn(o.z, MulRn(td, d.z / d_len))};
  }
  StreakPixel& out = f.splat.pixels[i];
  out.pixel = i;
  out.t = t;
  out.alpha = s.alpha;
  out.L = ShadeStreak(set, nullptr, p, ng, f.lights, f.num_lights, f.volume,
                      f.splat.streaks.sky_ambient);
}

/// pixel i's streak after the splat (f.splat: SplatStreakRow, ShadeSplatPixel), shaded (*s), if
/// it has one; false for a frame without streaks.
PB_HOST_DEVICE inline bool PixelStreakOf(const RealtimeFrameView& f, int64_t i, StreakPixel* s) {
  if (f.splat.streaks.num <= 0 || f.splat.nearest[i] == kNoStreakKey) return false;
  *s = f.splat.pixels[i];
  return true;
}

}  // namespace penumbra::cuda
