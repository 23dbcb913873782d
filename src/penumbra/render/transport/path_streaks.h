#pragma once
// the particle streaks (rain, snow, sparks) of a pathtraced frame as the path kernels trace
// them, written once as PB_HOST_DEVICE functions over plain data: the GPU (path_kernels.cu) and
// the CPU backend (render/cpu/path_tiles.h) run them. every streak is the capsule of
// ParticleStreaks (render/particles/particle_streaks.h: the segment a particle sweeps in the
// exposure, its widened radius); a BVH over the capsules' boxes (built on the host per
// frame by bvh_builder.h's binned SAH, path_streak_build.h) is traversed by the scene's own
// traversal (TraverseWideBvh) with Quilez's ray-capsule test (render/particles/particle_math.h's
// IntersectCapsule, which the realtime tier's splat calls too), and a hit streak is shaded by
// ParticleStreaks::Shade's ShadeStreak. C++17, no Eigen: path_kernels.cu includes it.

#include <cstdint>

#include "penumbra/core/host_device.h"
#include "penumbra/render/bvh/bvh_traversal.h"
#include "penumbra/render/bvh/bvh_types.h"
#include "penumbra/render/light/bsdf_math.h"
#include "penumbra/render/particles/particle_math.h"
#include "penumbra/render/shading_math.h"

namespace penumbra::cuda {

/// one streak: the capsule around [a, b] (world, m) of radius r (m, widened), its coverage
/// alpha in (0, 1], its index in the frame's ParticleStreaks (prim) and its particle set.
struct alignas(16) StreakPod {
  float a[3] = {0, 0, 0};
  float r = 0;
  float b[3] = {0, 0, 0};
  float alpha = 0;
  int32_t prim = 0;
  int32_t set = 0;
  int32_t pad[2] = {0, 0};
};
static_assert(sizeof(StreakPod) == 48, "StreakPod is three 16-byte loads");

/// a frame's streaks as the paths read them (host arrays or their device copies; num 0: none).
struct PathStreaks {
  int32_t num = 0;                     ///< streaks
  const BvhWideNode* nodes = nullptr;  ///< the BVH's inner nodes (root.num_nodes of them)
  Blas root;                           ///< the BVH's root box and reference (WidenBvh)
  const StreakPod* streaks = nullptr;  ///< num, in the BVH's leaf order
  const StreakSetPod* sets = nullptr;  ///< by EffectsFrame::particles index
  int32_t num_sets = 0;
  /// per streak (by StreakPod::prim) the rain radiance of ParticleStreaks::PrecomputeRain
  /// (cd/m^2), num_rain entries (0: none precomputed).
  const Float3* rain = nullptr;
  int32_t num_rain = 0;
  /// the open sky's sphere-average radiance (cd/m^2; SkyAmbientRadiance of the frame's sky),
  /// which the frame's sky volume occludes (ShadeStreak).
  Float3 sky_ambient;
};

/// the nearest streak along o + t d (d any length, t in units of |d|) with t in [tmin, tmax]:
/// true with *t_hit its t and *index its StreakPod (ps.streaks[*index]); false if none.
PB_HOST_DEVICE inline bool PathStreakHit(const PathStreaks& ps, const Float3& o, const Float3& d,
                                         float tmin, float tmax, float* t_hit, int* index) {
  if (ps.num <= 0) return false;
  const float len = sqrtf(EigenDot(d, d));
  const Float3 du{d.x / len, d.y / len, d.z / len};
  float t_max = tmax;
  int best = -1;
  auto leaf = [&](int k) {
    const StreakPod& s = ps.streaks[k];
    const CapsuleOrigin c =
        MakeCapsuleOrigin(o, Float3{s.a[0], s.a[1], s.a[2]}, Float3{s.b[0], s.b[1], s.b[2]}, s.r);
    const float t_m = IntersectCapsule(c, du);
    if (!(t_m > 0)) return false;
    const float t = t_m / len;
    if (!(t >= tmin && t <= t_max)) return false;
    t_max = t;
    best = k;
    return true;
  };
  if (!TraverseWideBvh(ps.nodes, ps.root, F3{o.x, o.y, o.z}, F3{d.x, d.y, d.z}, tmin, &t_max, false,
                       leaf))
    return false;
  *t_hit = t_max;
  *index = best;
  return true;
}

/// the radiance (cd/m^2) of streak `s` at its point p (world) hit by a ray of direction d:
/// ShadeStreak with the capsule's normal at p facing the ray (CapsuleNormal), rain's
/// precomputed radiance, the frame's `num_lights` lights and its sky volume.
PB_HOST_DEVICE inline Float3 PathStreakRadiance(const PathStreaks& ps, const StreakPod& s,
                                                const Float3& p, const Float3& d,
                                                const LightPod* lights, int num_lights,
                                                const SkyVolumePod& volume) {
  const StreakSetPod& set = ps.sets[s.set];
  const Float3 ng =
      CapsuleNormal(p, Float3{s.a[0], s.a[1], s.a[2]}, Float3{s.b[0], s.b[1], s.b[2]}, d);
  const Float3* rain = set.kind == StreakKind::kRain && s.prim >= 0 && s.prim < ps.num_rain
                           ? ps.rain + s.prim
                           : nullptr;
  return ShadeStreak(set, rain, p, ng, lights, num_lights, volume, ps.sky_ambient);
}

}  // namespace penumbra::cuda
