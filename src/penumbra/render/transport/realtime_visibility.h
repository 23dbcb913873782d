#pragma once
// the realtime tier's shared visibility of lights with an extent (lamp spheres, the sun's disc):
// each pixel's penumbra rays, the ratio estimator over its 5x5 same-surface window cut at the
// 16x16 tiles' edges and the resolve into the pixel's radiance (SharedVisibilityRays, Fraction,
// Resolve after ShadeRealtimePixel) over render/light/shadow_window_math.h. the per-pixel
// arithmetic is written once: the window masks (ShadowWindowMask), the penumbra rays' count and
// lattice points (PenumbraExtraRays, PenumbraPointIndex), the window's fraction
// (SharedWindowFraction), a lamp's 3x3 mean (SharedLampFraction) and the resolve
// (AddSharedVisibility); the CPU's ResolveSharedVisibility (render/cpu/realtime_integrator.cc)
// drives them per 16x16 tile over its own arrays, its penumbra rays as Embree packets.

#include <cstdint>

#include "penumbra/core/host_device.h"
#include "penumbra/render/bvh/bvh_traversal.h"
#include "penumbra/render/light/lamp_math.h"
#include "penumbra/render/light/shadow_window_math.h"
#include "penumbra/render/transport/realtime_shading.h"
#include "penumbra/render/transport/scene_view.h"

namespace penumbra::cuda {

/// the penumbra rays of a pixel whose window sees both verdicts towards a light with an extent:
/// *points = PenumbraLatticePoints(share) (share: the light's part of the pixel's unshadowed
/// luminance); returns `extra`, the rays r = 1 .. extra - 1 it traces after its first: on a
/// tile's outer ring (`own`: its window lacks the next tile's half) `points` points of its
/// own, else max(1, points / kLightStrata) (a window of 16 pixels then averages `points`).
PB_HOST_DEVICE inline int PenumbraExtraRays(float share, bool own, int* points) {
  *points = PenumbraLatticePoints(share);
  const int shared = *points / kLightStrata > 1 ? *points / kLightStrata : 1;
  return own ? *points : shared;
}

/// the index in the kLightStrata kLightPenumbraRays lattice (LightStratumUniforms) of penumbra
/// ray r of a pixel whose first point is `first` (kLightPenumbraRays LightStratum(u, v)):
/// PenumbraLatticeIndex of its `points` own points where `own`, else first + r.
PB_HOST_DEVICE inline int PenumbraPointIndex(int first, int r, int points, bool own) {
  return own ? PenumbraLatticeIndex(first, r, points) : first + r;
}

/// one light's penumbra rays at one pixel (SharedVisibilityRays): the pixel's own verdict and
/// the lattice points of its extra shadow rays r = 1 .. extra - 1.
struct PenumbraRays {
  Float3 p, ng;        ///< the pixel's hit point and unit geometric normal (PixelGeometry)
  int32_t first = 0;   ///< the pixel's first lattice point, kLightPenumbraRays LightStratum(u, v)
  int32_t points = 0;  ///< PenumbraLatticePoints of the light's share of the pixel's luminance
  int32_t extra = 0;   ///< rays r = 1 .. extra - 1 are traced (extra <= 1: none)
  int32_t own = 0;     ///< 1: a tile's outer ring (the pixel's own points, PenumbraLatticeIndex)
  int32_t active = 0;  ///< 1: the pixel traced a verdict towards a light with an extent
  float visible = 0;   ///< the pixel's own verdict (f.area_vis: 1 visible, 0 occluded)
};

/// the pixels' surfaces as the window masks read them (ShadowWindowMask): the frame's
/// PixelGeometry records at k.
struct FrameWindowSurfaces {
  const PixelGeometry* geometry = nullptr;
  /// whether the pixel at k has a hit.
  PB_HOST_DEVICE bool Hit(int64_t k) const { return geometry[k].hit != 0; }
  /// the geom of the pixel at k (which has a hit).
  PB_HOST_DEVICE int Geom(int64_t k) const { return geometry[k].geom; }
  /// the unit geometric normal and the hit point of the pixel at k (which has a hit).
  PB_HOST_DEVICE void Surface(int64_t k, float ng[3], float p[3]) const {
    const PixelGeometry& g = geometry[k];
    ng[0] = g.ng.x, ng[1] = g.ng.y, ng[2] = g.ng.z;
    p[0] = g.p_or_d.x, p[1] = g.p_or_d.y, p[2] = g.p_or_d.z;
  }
};

/// a shadow tile's copy of the surfaces FrameWindowSurfaces reads (the GPU's
/// VisibilityRaysWarpKernel keeps it in shared memory, one
/// entry a tile pixel, structure of arrays): key the geom of a hit, kNoWindowSurface where
/// the pixel has none (a miss or outside the image); the normal and point of a hit.
struct TileWindowSurfaces {
  static constexpr int32_t kNoWindowSurface = INT32_MIN;  ///< the key of a pixel without a hit
  const int32_t* key = nullptr;                           ///< a key a tile pixel
  const float *ng_x = nullptr, *ng_y = nullptr, *ng_z = nullptr;  ///< unit normals (world)
  const float *p_x = nullptr, *p_y = nullptr, *p_z = nullptr;     ///< hit points, m (world)
  /// the key of `g` (its geom where it has a hit, else kNoWindowSurface).
  PB_HOST_DEVICE static int32_t KeyOf(const PixelGeometry& g) {
    return g.hit != 0 ? g.geom : kNoWindowSurface;
  }
  /// whether the pixel at k has a hit.
  PB_HOST_DEVICE bool Hit(int64_t k) const { return key[k] != kNoWindowSurface; }
  /// the geom of the pixel at k (which has a hit).
  PB_HOST_DEVICE int Geom(int64_t k) const { return key[k]; }
  /// the unit geometric normal and the hit point of the pixel at k (which has a hit).
  PB_HOST_DEVICE void Surface(int64_t k, float ng[3], float p[3]) const {
    ng[0] = ng_x[k], ng[1] = ng_y[k], ng[2] = ng_z[k];
    p[0] = p_x[k], p[1] = p_y[k], p[2] = p_z[k];
  }
};

/// the window mask of tile-local pixel (x, y) of `tile` (the pixels of its 5x5 window, cut at
/// the tile's edges, on its surface: SameShadowSurface, ShadowWindowBit) whose surface is at
/// `at` of `s` (FrameWindowSurfaces or TileWindowSurfaces: Hit, Geom, Surface), its neighbour
/// (dx, dy) at at + dy stride + dx. 0 where the pixel has no hit.
template <class Surfaces>
PB_HOST_DEVICE inline uint32_t ShadowWindowMask(const Surfaces& s, int64_t at, int64_t stride,
                                                int x, int y, const ShadowTile& tile) {
  if (!s.Hit(at)) return 0;
  float ng_i[3], p_i[3];
  s.Surface(at, ng_i, p_i);
  const int geom_i = s.Geom(at);
  uint32_t bits = 0;
  for (int dy = -kShadowWindowRadius; dy <= kShadowWindowRadius; ++dy) {
    if (y + dy < 0 || y + dy >= tile.height) continue;
    for (int dx = -kShadowWindowRadius; dx <= kShadowWindowRadius; ++dx) {
      if (x + dx < 0 || x + dx >= tile.width) continue;
      const int64_t kk = at + static_cast<int64_t>(dy) * stride + dx;
      if (kk != at) {
        if (!s.Hit(kk)) continue;
        float ng_g[3], p_g[3];
        s.Surface(kk, ng_g, p_g);
        if (!SameShadowSurface(geom_i, ng_i, p_i, s.Geom(kk), ng_g, p_g)) continue;
      }
      bits |= 1u << ShadowWindowBit(dx, dy);
    }
  }
  return bits;
}

/// the shared visibility, step 1 of 3, first part: pixel (u, v)'s window mask (ShadowWindowMask)
/// with its surface at `at` of `s` (a tile's copy: TileWindowSurfaces, stride
/// kShadowTileSize), written to f.window and returned.
template <class Surfaces>
PB_HOST_DEVICE inline uint32_t SharedVisibilityWindow(const RealtimeFrameView& f, int u, int v,
                                                      const Surfaces& s, int64_t at,
                                                      int64_t stride) {
  const int W = f.camera.width, H = f.camera.height;
  const ShadowTile tile = ShadowTileOf(u, v, W, H);
  const uint32_t bits = ShadowWindowMask(s, at, stride, u - tile.x0, v - tile.y0, tile);
  f.window[static_cast<int64_t>(v) * W + u] = bits;
  return bits;
}

/// SharedVisibilityWindow with the surfaces read from the frame's f.geometry.
PB_HOST_DEVICE inline uint32_t SharedVisibilityWindow(const RealtimeFrameView& f, int u, int v) {
  return SharedVisibilityWindow(f, u, v, FrameWindowSurfaces{f.geometry},
                                static_cast<int64_t>(v) * f.camera.width + u, f.camera.width);
}

/// a light's verdicts around a pixel as SharedVisibilityPenumbra reads them: the pixel's own at
/// vis[at], its window neighbour (dx, dy)'s at vis[at + dy stride + dx] (the frame's f.area_vis
/// + j n).
struct StridedWindowVerdicts {
  const int8_t* vis = nullptr;  ///< 1 visible, 0 occluded, -1 none traced
  int64_t at = 0;               ///< the pixel's own entry
  int64_t stride = 0;           ///< the entries of one row (the image's width)
  /// the pixel's own verdict: 1, 0 or -1.
  PB_HOST_DEVICE int Own() const { return vis[at]; }
  /// whether the window mask `bits` holds a verdict 1 (seen[1]) and 0 (seen[0]): each set bit's
  /// verdict in turn.
  PB_HOST_DEVICE void Seen(uint32_t bits, bool seen[2]) const {
    seen[0] = seen[1] = false;
    for (uint32_t b = bits; b != 0; b &= b - 1) {
      const int bit = LowestSetBit(b);
      const int8_t w = vis[at + static_cast<int64_t>(bit / 5 - 2) * stride + (bit % 5 - 2)];
      if (w >= 0) seen[w] = true;
    }
  }
};

/// a light's verdicts of a shadow tile as bit rows (kShadowVerdictRows words,
/// render/light/shadow_window_math.h; the GPU's VisibilityRaysWarpKernel keeps them in shared
/// memory) around tile pixel (x, y): the same values as StridedWindowVerdicts over the
/// frame's f.area_vis.
struct RowWindowVerdicts {
  const uint32_t* rows = nullptr;  ///< kShadowVerdictRows words (ShadowVerdictBits)
  int x = 0, y = 0;                ///< the pixel in its tile (column, row)
  /// the pixel's own verdict: 1, 0 or -1 (ShadowRowVerdict).
  PB_HOST_DEVICE int Own() const { return ShadowRowVerdict(rows, x, y); }
  /// whether the window mask `bits` holds a verdict 1 (seen[1]) and 0 (seen[0])
  /// (ShadowWindowVerdicts: five shifted rows).
  PB_HOST_DEVICE void Seen(uint32_t bits, bool seen[2]) const {
    ShadowWindowVerdicts(rows, x, y, bits, seen);
  }
};

/// the shared visibility, step 1 of 3, second part: light j's penumbra rays at pixel (u, v)
/// whose window mask is `bits` (SharedVisibilityWindow). inactive (active 0) where the pixel
/// traced no verdict towards j or j has no extent; where the verdicts in the window disagree (a
/// penumbra), as many rays as the light's share of the pixel's unshadowed luminance asks for
/// (PenumbraLatticePoints, render/light/lamp_math.h, as the CPU's ResolveSharedVisibility): on a
/// tile's outer ring the pixel's own points - 1 more (f.area_own set: that pixel keeps its own
/// fraction), else max(1, points / kLightStrata) - 1 more after its first. writes f.area_own.
/// the window's verdicts of light j come from `w` (Own, Seen): StridedWindowVerdicts over the
/// frame's f.area_vis, or RowWindowVerdicts over a tile's bit rows.
template <class Verdicts>
PB_HOST_DEVICE inline PenumbraRays SharedVisibilityPenumbraOf(const RealtimeFrameView& f, int u,
                                                              int v, int j, uint32_t bits,
                                                              const Verdicts& w) {
  const int W = f.camera.width, H = f.camera.height;
  const int64_t n = static_cast<int64_t>(W) * H;
  const int64_t i = static_cast<int64_t>(v) * W + u;
  const int64_t k = j * n + i;
  PenumbraRays job;
  f.area_own[k] = 0;
  if (!IsExtendedLightPod(f.lights[j])) return job;
  const int vis = w.Own();
  if (vis < 0) return job;
  job.active = 1;
  job.visible = static_cast<float>(vis);
  bool seen[2];
  w.Seen(bits, seen);
  if (!(seen[0] && seen[1])) return job;
  const ShadowTile tile = ShadowTileOf(u, v, W, H);
  const bool own = OnShadowTileRing(u - tile.x0, v - tile.y0, tile);
  f.area_own[k] = own ? 1 : 0;
  const Float3 c = f.area_c[k];
  int points;
  const int extra = PenumbraExtraRays(pbm::Luminance709(c.x, c.y, c.z) / f.total[i], own, &points);
  const PixelGeometry& gi = f.geometry[i];
  job.p = gi.p_or_d;
  job.ng = gi.ng;
  job.first = kLightPenumbraRays * LightStratum(u, v);
  job.points = points;
  job.extra = extra;
  job.own = own ? 1 : 0;
  return job;
}

/// SharedVisibilityPenumbraOf with the window's verdicts of light j read from the frame's
/// f.area_vis (StridedWindowVerdicts).
PB_HOST_DEVICE inline PenumbraRays SharedVisibilityPenumbra(const RealtimeFrameView& f, int u,
                                                            int v, int j, uint32_t bits) {
  const int64_t n = static_cast<int64_t>(f.camera.width) * f.camera.height;
  return SharedVisibilityPenumbraOf(
      f, u, v, j, bits,
      StridedWindowVerdicts{f.area_vis + j * n, static_cast<int64_t>(v) * f.camera.width + u,
                            f.camera.width});
}

/// penumbra ray r (1 <= r < job.extra) of light j (SharedVisibilityPenumbra): -1 where no ray
/// is traced (the light sends nothing to the point, or the direction lies below its geometric
/// surface), else 1 visible, 0 occluded.
PB_HOST_DEVICE inline int PenumbraRayVerdict(const RealtimeFrameView& f, int j,
                                             const PenumbraRays& job, int r) {
  constexpr int kAll = kLightStrata * kLightPenumbraRays;
  float u1, u2, d_r;
  Float3 w_r, E_r;
  bool ok;
  LightStratumUniforms(PenumbraPointIndex(job.first, r, job.points, job.own != 0), kAll, &u1, &u2);
  SampleLight<float, Float3, bool>(f.lights[j], job.p, u1, u2, &w_r, &d_r, &E_r, &ok);
  if (!ok || !(pbm::Dot<float>(w_r, job.ng) > 0)) return -1;
  TraceRay sr;
  sr.o = OffsetOrigin(job.p, job.ng);
  sr.tmin = 0;
  sr.d = ToF3(w_r);
  sr.tmax = d_r * (1.0f - 1e-4f);  // +inf stays +inf
  return TraceOccluded(f.scene, sr) ? 0 : 1;
}

/// light j's penumbra rays r0 .. r1 - 1 of `job` in turn (PenumbraRayVerdict): *traced, how
/// many were traced, and *visible, how many of those reached the light.
PB_HOST_DEVICE inline void CountPenumbraRays(const RealtimeFrameView& f, int j,
                                             const PenumbraRays& job, int r0, int r1, int* traced,
                                             int* visible) {
  *traced = *visible = 0;
  for (int r = r0; r < r1; ++r) {
    const int verdict = PenumbraRayVerdict(f, j, job, r);
    if (verdict < 0) continue;
    ++*traced;
    if (verdict > 0) ++*visible;
  }
}

/// the window's verdicts of every light as SharedVisibilityRaysOf takes them: light j's at
/// vis + j light_stride around `at` (StridedWindowVerdicts).
struct StridedLightVerdicts {
  const int8_t* vis = nullptr;
  int64_t light_stride = 0, at = 0, stride = 0;
  /// light j's verdicts.
  PB_HOST_DEVICE StridedWindowVerdicts operator()(int j) const {
    return StridedWindowVerdicts{vis + j * light_stride, at, stride};
  }
};

/// every light's bit rows of a shadow tile (kShadowVerdictRows words each, light after light)
/// around tile pixel (x, y) as SharedVisibilityRaysOf takes them (RowWindowVerdicts).
struct RowLightVerdicts {
  const uint32_t* rows = nullptr;
  int x = 0, y = 0;
  /// light j's verdicts.
  PB_HOST_DEVICE RowWindowVerdicts operator()(int j) const {
    return RowWindowVerdicts{rows + j * kShadowVerdictRows, x, y};
  }
};

/// the shared visibility, step 1 of 3 (after ShadeRealtimePixel at every pixel): pixel (u,
/// v)'s window mask (SharedVisibilityWindow over the surfaces `s` at `at`, `stride`) and, per
/// light with an extent, its penumbra rays in order (SharedVisibilityPenumbraOf over light j's
/// verdicts `verdicts(j)`: StridedLightVerdicts or RowLightVerdicts; PenumbraRayVerdict);
/// f.area_visible, f.area_rays: the pixel's visible and traced rays (its own verdict
/// included). the GPU's VisibilityRaysWarpKernel spreads a warp's penumbra rays over its lanes
/// and sums the same integer counts.
template <class Surfaces, class LightVerdicts>
PB_HOST_DEVICE inline void SharedVisibilityRaysOf(const RealtimeFrameView& f, int u, int v,
                                                  const Surfaces& s, int64_t at, int64_t stride,
                                                  const LightVerdicts& verdicts) {
  const int64_t n = static_cast<int64_t>(f.camera.width) * f.camera.height;
  const int64_t i = static_cast<int64_t>(v) * f.camera.width + u;
  const uint32_t bits = SharedVisibilityWindow(f, u, v, s, at, stride);
  for (int j = 0; j < f.num_lights; ++j) {
    const PenumbraRays job = SharedVisibilityPenumbraOf(f, u, v, j, bits, verdicts(j));
    if (job.active == 0) continue;
    int traced, visible;
    CountPenumbraRays(f, j, job, 1, job.extra, &traced, &visible);
    // integer counts: the same sums as one ray at a time in float
    f.area_visible[j * n + i] = job.visible + static_cast<float>(visible);
    f.area_rays[j * n + i] = 1.0f + static_cast<float>(traced);
  }
}

/// SharedVisibilityRaysOf with the surfaces of the frame's f.geometry and the window's verdicts
/// of light j read at vis + j light_stride (SharedVisibilityPenumbra's vis_j, at and stride):
/// the frame's f.area_vis, or a tile's copy.
PB_HOST_DEVICE inline void SharedVisibilityRays(const RealtimeFrameView& f, int u, int v,
                                                const int8_t* vis, int64_t light_stride, int64_t at,
                                                int64_t stride) {
  SharedVisibilityRaysOf(f, u, v, FrameWindowSurfaces{f.geometry},
                         static_cast<int64_t>(v) * f.camera.width + u, f.camera.width,
                         StridedLightVerdicts{vis, light_stride, at, stride});
}

/// SharedVisibilityRays with the window's verdicts read from the frame's f.area_vis.
PB_HOST_DEVICE inline void SharedVisibilityRays(const RealtimeFrameView& f, int u, int v) {
  const int W = f.camera.width;
  SharedVisibilityRays(f, u, v, f.area_vis, static_cast<int64_t>(W) * f.camera.height,
                       static_cast<int64_t>(v) * W + u, W);
}

/// one light's shared-visibility arrays as SharedWindowFraction and SharedLampFraction read
/// them: the pixel at `at` has its window neighbour (dx, dy) at at + dy stride + dx. the
/// frame's arrays (f.area_* + j n, `at` the pixel's index, stride the image's width) or a
/// shadow tile's copy (the GPU's VisibilityTileKernel: shared memory, stride kShadowTileSize).
struct VisibilityTaps {
  const int8_t* vis = nullptr;      ///< f.area_vis: 1 visible, 0 occluded, -1 none traced
  const float* visible = nullptr;   ///< f.area_visible
  const float* rays = nullptr;      ///< f.area_rays
  const float* fraction = nullptr;  ///< f.area_fraction (SharedLampFraction)
  int64_t stride = 0;
  /// the pixels' ShadowWindowCounts of vis, visible and rays, packed once (a tile's copy), or
  /// null: packed from them at each tap (WindowTapCounts)
  const uint32_t* counts = nullptr;
};

/// the ShadowWindowCounts of the pixel at kk of t: t.counts's, or packed from t's arrays.
PB_HOST_DEVICE inline uint32_t WindowTapCounts(const VisibilityTaps& t, int64_t kk) {
  if (t.counts != nullptr) return t.counts[kk];
  return ShadowWindowCounts(t.vis[kk], t.visible[kk], t.rays[kk]);
}

/// the fraction of visible rays at the pixel at `at` (which traced a verdict) with window mask
/// `window`: its own (visible / rays) where `own` (a tile's outer ring in a penumbra), else the
/// window's weighted sum of visible rays over its weighted sum of rays (ShadowWindowWeight,
/// neighbours without a verdict left out). the sums in integers over the 25 taps, each tap's
/// counts packed in one word (WindowTapCounts, ShadowWindowSumFraction: exactly the float sums
/// in the window's bit order, whatever the order of the integer adds).
PB_HOST_DEVICE inline float SharedWindowFraction(const VisibilityTaps& t, int64_t at,
                                                 uint32_t window, bool own) {
  if (own) return ShadowWindowSumFraction(WindowTapCounts(t, at));
  uint32_t sum = 0;
#if defined(__CUDA_ARCH__)
#pragma unroll
#endif
  for (int bit = 0; bit < kShadowWindowTaps; ++bit) {
    if ((window >> bit & 1u) == 0) continue;
    const int dy = bit / 5 - 2, dx = bit % 5 - 2;
    sum += ShadowWindowWeight4(dx, dy) *
           WindowTapCounts(t, at + static_cast<int64_t>(dy) * t.stride + dx);
  }
  return ShadowWindowSumFraction(sum);
}

/// the visibility V the resolve gives the pixel at `at` (which traced a verdict), tile-local
/// (x, y) of `tile`, window mask `window`: its fraction (SharedWindowFraction, t.fraction), for
/// a lamp (`lamp`: not directional, and the pixel keeps no fraction of its own) the mean of
/// the fractions of the 3x3 pixels around it in its tile that lie in its window and traced a
/// verdict (a lamp's penumbrae are tens of pixels wide; the sun's stay as they are).
PB_HOST_DEVICE inline float SharedLampFraction(const VisibilityTaps& t, int64_t at, uint32_t window,
                                               bool lamp, int x, int y, const ShadowTile& tile) {
  if (!lamp) return t.fraction[at];
  float sum = 0;
  int count = 0;
  for (int yy = y - 1 < 0 ? 0 : y - 1; yy <= (y + 1 < tile.height ? y + 1 : tile.height - 1); ++yy)
    for (int xx = x - 1 < 0 ? 0 : x - 1; xx <= (x + 1 < tile.width ? x + 1 : tile.width - 1);
         ++xx) {
      const int64_t kk = at + static_cast<int64_t>(yy - y) * t.stride + (xx - x);
      if (t.vis[kk] < 0 || (window >> ShadowWindowBit(xx - x, yy - y) & 1u) == 0) continue;
      sum += t.fraction[kk];
      ++count;
    }
  return sum / static_cast<float>(count);
}

/// radiance L plus V times a light's unshadowed contribution c where V > 0 (the resolve).
PB_HOST_DEVICE inline Float3 AddSharedVisibility(const Float3& L, float V, const Float3& c) {
  if (!(V > 0)) return L;
  return Float3{L.x + V * c.x, L.y + V * c.y, L.z + V * c.z};
}

/// frame f's shared-visibility arrays from entry k = j n + i on (light j at pixel i) as
/// VisibilityTaps: pixel i's entry at 0, its neighbours around it (stride: the image's width).
PB_HOST_DEVICE inline VisibilityTaps FrameVisibilityTaps(const RealtimeFrameView& f, int64_t k) {
  VisibilityTaps t;
  t.vis = f.area_vis + k;
  t.visible = f.area_visible + k;
  t.rays = f.area_rays + k;
  t.fraction = f.area_fraction + k;
  t.stride = f.camera.width;
  return t;
}

/// the shared visibility, step 2 of 3 (after SharedVisibilityRays at every pixel): per light
/// with an extent that pixel (u, v) traced a verdict towards, the weighted fraction of visible
/// rays over its window (ShadowWindowWeight), or its own fraction on a tile's ring in a
/// penumbra (f.area_fraction; SharedWindowFraction).
PB_HOST_DEVICE inline void SharedVisibilityFraction(const RealtimeFrameView& f, int u, int v) {
  const int W = f.camera.width;
  const int64_t n = static_cast<int64_t>(W) * f.camera.height;
  const int64_t i = static_cast<int64_t>(v) * W + u;
  for (int j = 0; j < f.num_lights; ++j) {
    const int64_t k = j * n + i;
    if (!IsExtendedLightPod(f.lights[j]) || f.area_vis[k] < 0) continue;
    f.area_fraction[k] =
        SharedWindowFraction(FrameVisibilityTaps(f, k), 0, f.window[i], f.area_own[k] != 0);
  }
}

/// the shared visibility, step 3 of 3 (after SharedVisibilityFraction at every pixel): pixel
/// (u, v)'s radiance L plus, per light with an extent, V times its unshadowed contribution, V
/// the window's fraction, for a lamp once more averaged over the 3x3 pixels of its tile on the
/// same surface (SharedLampFraction, AddSharedVisibility).
PB_HOST_DEVICE inline Float3 SharedVisibilityResolve(const RealtimeFrameView& f, int u, int v,
                                                     Float3 L) {
  const int W = f.camera.width, H = f.camera.height;
  const int64_t n = static_cast<int64_t>(W) * H;
  const int64_t i = static_cast<int64_t>(v) * W + u;
  const ShadowTile tile = ShadowTileOf(u, v, W, H);
  const int x = u - tile.x0, y = v - tile.y0;
  for (int j = 0; j < f.num_lights; ++j) {
    const int64_t k = j * n + i;
    if (!IsExtendedLightPod(f.lights[j]) || f.area_vis[k] < 0) continue;
    const bool lamp = f.lights[j].kind != LightKind::kDirectional && f.area_own[k] == 0;
    const float V = SharedLampFraction(FrameVisibilityTaps(f, k), 0, f.window[i], lamp, x, y, tile);
    L = AddSharedVisibility(L, V, f.area_c[k]);
  }
  return L;
}

}  // namespace penumbra::cuda
