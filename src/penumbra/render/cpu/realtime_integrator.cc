#include "penumbra/render/cpu/realtime_integrator.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "penumbra/render/cpu/bsdf_lanes.h"
#include "penumbra/render/cpu/mirror_layer.h"
#include "penumbra/render/cpu/shadow_window_lanes.h"
#include "penumbra/render/light/brdf_math.h"
#include "penumbra/render/light/bsdf.h"
#include "penumbra/render/light/lamp_math.h"
#include "penumbra/render/light/shadow_window_math.h"
#include "penumbra/render/media/media_common.h"
#include "penumbra/render/particles/particle_math.h"
#include "penumbra/render/transport/realtime_visibility.h"

namespace penumbra {
namespace {

inline Lanes LuminanceLanes(const Vec3Lanes& c) { return pbm::Luminance709(c.x, c.y, c.z); }

// per-thread scratch, sized once per light count and reused across tiles and frames.
struct Scratch {
  std::vector<LightSampleLanes> samples;  // per light
  std::vector<Vec3Lanes> contrib;         // per light: unshadowed f cos E
  std::vector<Eigen::Vector3f> wo;        // per tile pixel: unit direction towards the camera
  std::vector<Eigen::Vector3f> n_s;       // per tile pixel: usable shading normal
  std::vector<Eigen::Vector3f> sky_E;     // per tile pixel: sky irradiance on n_s
  // lights with an extent (IsExtendedLight), per light j and tile pixel i at [j n + i]: the
  // unshadowed contribution waiting for the shared visibility (ResolveSharedVisibility) and the
  // pixel's own shadow ray's verdict (1 visible, 0 occluded, -1 none traced).
  std::vector<Eigen::Vector3f> area_c;
  std::vector<int8_t> area_vis;
  // per light: the verdicts in area_vis of the tile, bit 0 an occluded one, bit 1 a visible one.
  std::vector<uint8_t> area_seen;
  std::vector<float> mirror;  // per tile pixel: SurfaceMaterial::mirror, 0 = none
  std::vector<float> total;   // per tile pixel: luminance of the radiance, all lights unshadowed
};

// shadow rays per pixel towards a light with an extent in a penumbra (1 elsewhere).
constexpr int kPenumbraRays = kLightPenumbraRays;

// a light with an extent: a sphere lamp (radius > 0) or the sun's disc. its unshadowed light is
// analytic (render/light/lamp_math.h; the transport's ExtendedLightAxisOf and
// ExtendedLightContribution, render/transport/realtime_shading.h) and its visibility shared over
// 5x5 pixels.
bool IsExtendedLight(const FrameContext& ctx, int j) {
  return cuda::IsExtendedLightPod(ctx.lights->pods()[j]);
}

// adds the extended lights' contributions of a tile to its radiance: pixel i's light j counts
// c_ij times the fraction of visible shadow rays over the 5x5 pixels around it (weights 1/2 on
// the outer rows and columns, so each pixel of a 4x4 lattice block weighs 1; cut at the tile's
// edges, where fewer lattice points are averaged) that lie on the same surface as pixel i (same
// geom, normals within 25 degrees, within 5 % of their distance from its tangent plane) and traced
// towards j (the ratio estimator of Heitz et al. 2018 with the shadow term shared). a pixel whose
// window holds both visible and occluded verdicts (a penumbra) traces more rays through its other
// lattice points first, as many as the light's share of its unshadowed luminance asks for
// (PenumbraLatticePoints, render/light/lamp_math.h: up to kPenumbraRays - 1 more, so that a window
// there averages up to 64 points, not 16); a lamp's visible fraction is then averaged once more
// over 3x3 pixels on the same surface. the windows are tested as bit masks (one 32-bit word per
// tile row, EmbreeRenderer::kTileSize <= 28), and a window or 3x3 block whose verdicts agree
// takes that verdict without summing. adds the rays traced to *traced.
void ResolveSharedVisibility(const FrameContext& ctx, const PrimaryHits& primary,
                             const Scratch& scratch, const FrameBuffers& out, int64_t* traced) {
  const PixelTile& tile = primary.tile;
  const ShadowTile shadow_tile{tile.x0, tile.y0, tile.width, tile.height};
  const int n = tile.width * tile.height;
  const int num_lights = ctx.lights->size();
  thread_local std::vector<float> visible, rays, fraction;
  thread_local std::vector<uint8_t> own;                  // 1: the pixel's own fraction, no window
  thread_local std::vector<uint8_t> mixed, seen_visible;  // per pixel: its window's verdicts
  own.resize(n);
  visible.resize(n);
  rays.resize(n);
  fraction.resize(n);
  struct {
    Vec3Lanes p, ng;  // the pixels' hit points and geometric normals
    Lanes u1, u2;     // their lattice points (LightStratumUniforms)
    int pixel[kLanes];
  } queue;
  mixed.resize(n);
  seen_visible.resize(n);
  bool any = false;
  for (int j = 0; j < num_lights; ++j) any = any || IsExtendedLight(ctx, j);
  if (!any) return;
  // every pixel's column and row in the tile.
  thread_local std::vector<uint8_t> xs, ys;
  xs.resize(n), ys.resize(n);
  for (int y = 0, i = 0; y < tile.height; ++y)
    for (int x = 0; x < tile.width; ++x, ++i)
      xs[i] = static_cast<uint8_t>(x), ys[i] = static_cast<uint8_t>(y);
  // per pixel, which pixels of the window [x - 2, x + 2] x [y - 2, y + 2], cut at the tile's
  // edges, lie on its surface (bit (dy + 2) 5 + dx + 2), once for all lights. (shifting the
  // window inside the tile instead made steps of several % at every tile edge across a lamp's
  // penumbra.)
  thread_local std::vector<uint32_t> near;
  thread_local std::vector<float> hit_p, hit_n;  // per pixel: p_W and ng_W, xyz
  thread_local std::vector<int> hit_geom;        // per pixel: the geom, -1 none
  bool near_done = false;
  auto compute_near = [&] {
    near_done = true;
    near.resize(n);
    // the hits' points, normals and geoms side by side (the hits themselves are large), then
    // the masks with a tile row's pixels as SIMD lanes (render/cpu/shadow_window_lanes.h).
    hit_p.resize(3 * n), hit_n.resize(3 * n), hit_geom.resize(n);
    for (int i = 0; i < n; ++i) {
      const SurfaceHit& h = primary.hits[i];
      hit_geom[i] = primary.did_hit[i] ? h.geom : -1;
      for (int a = 0; a < 3; ++a) hit_p[3 * i + a] = h.p_W[a], hit_n[3 * i + a] = h.ng_W[a];
    }
    SameSurfaceWindowsLanes(tile.width, tile.height, primary.did_hit, hit_geom.data(), hit_p.data(),
                            hit_n.data(), near.data());
  };
  // the bits of pixel (x, y)'s window (as near[i]) that are set in `rows` (bit x of rows[y]:
  // pixel (x, y)).
  auto window_bits = [&](const uint32_t* rows, int x, int y) {
    uint32_t w = 0;
    for (int dy = -2; dy <= 2; ++dy) {
      const int yy = y + dy;
      if (yy < 0 || yy >= tile.height) continue;
      w |= (((rows[yy] << 2) >> x) & 31u) << ((dy + 2) * 5);
    }
    return w;
  };
  // per tile row, bit x: pixels with an occluded verdict, a visible one, more than one ray.
  thread_local std::vector<uint32_t> rows_occluded, rows_visible, rows_more;
  rows_occluded.resize(tile.height), rows_visible.resize(tile.height),
      rows_more.resize(tile.height);
  // per tile row, bit x: pixels with a fraction, with fraction 1, with fraction 0.
  thread_local std::vector<uint32_t> rows_has, rows_lit, rows_dark;
  rows_has.resize(tile.height), rows_lit.resize(tile.height), rows_dark.resize(tile.height);
  auto fill_rows = [&](const int8_t* vis) {
    for (int y = 0; y < tile.height; ++y) {
      uint32_t o = 0, v = 0;
      for (int x = 0; x < tile.width; ++x) {
        const int8_t b = vis[y * tile.width + x];
        o |= static_cast<uint32_t>(b == 0) << x;
        v |= static_cast<uint32_t>(b == 1) << x;
      }
      rows_occluded[y] = o, rows_visible[y] = v, rows_more[y] = 0;
    }
  };

  for (int j = 0; j < num_lights; ++j) {
    if (!IsExtendedLight(ctx, j)) continue;
    const int8_t* vis = &scratch.area_vis[static_cast<size_t>(j) * n];
    const Eigen::Vector3f* c = &scratch.area_c[static_cast<size_t>(j) * n];
    // the shadow rays through further lattice points, kLanes at a time: their directions as
    // lanes (LightSampler::SampleLanes) and one Embree packet (a pixel's rays share their origin
    // and go to one light: coherent). point(i, index) queues pixel i's ray through point `index`
    // of the 64-point lattice (the pixel's own point r of `points`, PenumbraLatticeIndex, or its
    // point first + r inside a window); flush() traces the queue and adds to rays[] and
    // visible[] the rays whose point lies above the geometric surface and their verdicts.
    int queued = 0;
    auto flush = [&] {
      if (queued == 0) return;
      for (int k = queued; k < kLanes; ++k) {  // idle lanes repeat the first
        queue.p.Set(k, queue.p.Lane(0)), queue.ng.Set(k, queue.ng.Lane(0));
        queue.u1[k] = queue.u1[0], queue.u2[k] = queue.u2[0];
      }
      LightSampleLanes ls;
      ctx.lights->SampleLanes(j, queue.p, queue.u1, queue.u2, &ls);
      const LaneMask active =
          LaneMask((1u << queued) - 1u) && ls.valid && GreaterThan(queue.ng.Dot(ls.wi), 0.0f);
      Vec3Lanes o;
      for (int k = 0; k < kLanes; ++k) o.Set(k, OffsetRayOrigin(queue.p.Lane(k), queue.ng.Lane(k)));
      const Lanes tmax = ls.distance * (1.0f - 1e-4f);  // +inf stays +inf
      LaneMask occluded;
      if (active.any()) ctx.scene->OccludedLanes(o, ls.wi, tmax, active, &occluded);
      *traced += active.count();
      for (int k = 0; k < queued; ++k) {
        if (!active[k]) continue;
        rays[queue.pixel[k]] += 1;
        if (!occluded[k]) visible[queue.pixel[k]] += 1;
      }
      queued = 0;
    };
    auto trace_point = [&](int i, int index) {
      LightStratumUniforms(index, kLightStrata * kPenumbraRays, &queue.u1[queued],
                           &queue.u2[queued]);
      queue.p.Set(queued, primary.hits[i].p_W);
      queue.ng.Set(queued, primary.hits[i].ng_W);
      queue.pixel[queued] = i;
      if (++queued == kLanes) flush();
    };
    auto first_point = [&](int i) {
      return kPenumbraRays * LightStratum(tile.x0 + xs[i], tile.y0 + ys[i]);
    };
    const uint8_t seen_in_tile = scratch.area_seen[j];
    if (seen_in_tile != 3) {
      // every verdict towards j in the tile agrees (most tiles): every window's fraction is that
      // verdict, exactly.
      if ((seen_in_tile & 2) == 0) continue;
      for (int i = 0; i < n; ++i) {
        if (vis[i] < 0) continue;
        float* Lp = out.radiance->at(tile.x0 + xs[i], tile.y0 + ys[i]);
        Lp[0] += c[i].x(), Lp[1] += c[i].y(), Lp[2] += c[i].z();
      }
      continue;
    }
    if (!near_done) compute_near();
    fill_rows(vis);
    for (int i = 0; i < n; ++i) {
      if (vis[i] < 0) continue;
      visible[i] = static_cast<float>(vis[i]);
      rays[i] = 1;
      const uint32_t wo = near[i] & window_bits(rows_occluded.data(), xs[i], ys[i]);
      const uint32_t wv = near[i] & window_bits(rows_visible.data(), xs[i], ys[i]);
      seen_visible[i] = wv != 0;
      own[i] = 0;
      mixed[i] = wo != 0 && wv != 0;
      if (!mixed[i]) continue;
      // a penumbra: the pixel's other lattice points, as many as the light's share of the
      // pixel's unshadowed luminance asks for (PenumbraLatticePoints: 64 points for a light
      // that dominates the pixel, fewer for a faint one, whose visibility moves the pixel
      // little): max(1, points / 16) per pixel of a window of 16. on the tile's outermost
      // pixels, whose window lacks the next tile's half, `points` points of their own instead,
      // and the pixel keeps its own fraction (a window cut there leans inwards: steps at tile
      // edges).
      const int x = xs[i], y = ys[i];
      const int first = first_point(i);
      const float share = pbm::Luminance709(c[i].x(), c[i].y(), c[i].z()) / scratch.total[i];
      own[i] = OnShadowTileRing(x, y, shadow_tile);
      int points;
      const int extra = cuda::PenumbraExtraRays(share, own[i] != 0, &points);
      for (int r = 1; r < extra; ++r)
        trace_point(i, cuda::PenumbraPointIndex(first, r, points, own[i] != 0));
      if (extra > 1) rows_more[y] |= 1u << x;
    }
    flush();
    std::fill(rows_has.begin(), rows_has.end(), 0u);
    std::fill(rows_lit.begin(), rows_lit.end(), 0u);
    std::fill(rows_dark.begin(), rows_dark.end(), 0u);
    auto note_fraction = [&](int i) {
      const uint32_t bit = 1u << xs[i];
      rows_has[ys[i]] |= bit;
      if (fraction[i] == 1.0f) rows_lit[ys[i]] |= bit;
      if (fraction[i] == 0.0f) rows_dark[ys[i]] |= bit;
    };
    // the tile's arrays as the transport's taps (stride: the tile's width).
    cuda::VisibilityTaps taps;
    taps.vis = vis;
    taps.visible = visible.data();
    taps.rays = rays.data();
    taps.fraction = fraction.data();
    taps.stride = tile.width;
    for (int i = 0; i < n; ++i) {
      if (vis[i] < 0) continue;
      if (own[i]) {
        fraction[i] = cuda::SharedWindowFraction(taps, i, near[i], true);
        note_fraction(i);
        continue;
      }
      // a window of agreeing verdicts of one ray each: that verdict, exactly.
      if (!mixed[i] && (near[i] & window_bits(rows_more.data(), xs[i], ys[i])) == 0) {
        fraction[i] = seen_visible[i] ? 1.0f : 0.0f;
        note_fraction(i);
        continue;
      }
      fraction[i] = cuda::SharedWindowFraction(taps, i, near[i], false);
      note_fraction(i);
    }
    // a lamp's penumbrae (tens of pixels wide next to its fixture) once more over the 3x3
    // pixels on the same surface: the 5x5 windows' 16 lattice points leave 4-pixel steps
    // along them. the sun's (a pixel or two wide) stay as they are.
    const bool smooth = ctx.lights->lights()[j].type != Light::Type::kDirectional;
    // the 3x3 pixels around a window's centre (bits as near[i]).
    constexpr uint32_t kInner3x3 = (7u << 6) | (7u << 11) | (7u << 16);
    for (int i = 0; i < n; ++i) {
      if (vis[i] < 0) continue;
      float V = fraction[i];
      const int x = xs[i], y = ys[i];
      if (smooth && !own[i]) {
        // the same-surface pixels of the 3x3 all fully visible or all occluded (most): V is that.
        const uint32_t nb = near[i] & kInner3x3 & window_bits(rows_has.data(), x, y);
        if ((nb & ~window_bits(rows_lit.data(), x, y)) == 0) {
          V = 1.0f;
        } else if ((nb & ~window_bits(rows_dark.data(), x, y)) == 0) {
          V = 0.0f;
        } else {
          V = cuda::SharedLampFraction(taps, i, near[i], true, x, y, shadow_tile);
        }
      }
      if (!(V > 0)) continue;
      float* Lp = out.radiance->at(tile.x0 + x, tile.y0 + y);
      const Float3 L = cuda::AddSharedVisibility(Float3{Lp[0], Lp[1], Lp[2]}, V,
                                                 Float3{c[i].x(), c[i].y(), c[i].z()});
      Lp[0] = L.x, Lp[1] = L.y, Lp[2] = L.z;
    }
  }
}

// walks the tile by 2x2 pixel quads, row-major: shared(q) is offered every quad that lies fully
// inside the tile (q = its 4 pixel indices, row-major) and returns whether it handled the quad;
// single(i) is called for every pixel of the other quads, and of quads shared() declined.
template <typename SharedFn, typename SingleFn>
void ForEachQuad(const PixelTile& tile, SharedFn&& shared, SingleFn&& single) {
  for (int y = 0; y < tile.height; y += 2) {
    for (int x = 0; x < tile.width; x += 2) {
      const int i00 = y * tile.width + x;
      const int q[4] = {i00, i00 + 1, i00 + tile.width, i00 + tile.width + 1};
      if (x + 1 < tile.width && y + 1 < tile.height && shared(x, y, q)) continue;
      for (int c = 0; c < 4; ++c) {
        const int dx = c & 1, dy = c >> 1;
        if (x + dx < tile.width && y + dy < tile.height) single(q[c]);
      }
    }
  }
}

// the sky irradiance on the shading normal of every hit pixel of the tile (the ambient term),
// and that normal. with a sky volume (occluded sky light), the probe weights and their mean SH
// (SkyIrradianceVolume::Blend) follow the surface's position and geometric normal, and only
// the SH evaluation the shading normal: a 2x2 quad of pixels that all see one flat face (one
// geom, bitwise equal geometric normals, points on one plane within 1 mm and within a quarter
// probe spacing of each other) shares one blend at the quad's mean point; the volume
// interpolates probes one spacing apart (0.43 m in the default world), so across a quad it
// changes by far less than the 8-bit output resolves, and the blend is the costliest per-pixel
// term of the tier. every pixel then evaluates the blend at its own shading normal (normal
// maps vary it from pixel to pixel). other quads (edges, curved faces) blend every pixel.
void TileSkyIrradiance(const FrameContext& ctx, const PrimaryHits& primary, Scratch* scratch) {
  const PixelTile& tile = primary.tile;
  const int n = tile.width * tile.height;
  scratch->wo.resize(n);
  scratch->n_s.resize(n);
  scratch->sky_E.resize(n);
  for (int i = 0; i < n; ++i) {
    if (!primary.did_hit[i]) continue;
    const SurfaceHit& h = primary.hits[i];
    scratch->wo[i] = -primary.rays[i].d.normalized();
    scratch->n_s[i] = UsableShadingNormal(h.ns_W, h.ng_W, scratch->wo[i]);
  }
  const SkyIrradianceVolume* volume = ctx.sky_volume;
  if (volume == nullptr) {
    for (int i = 0; i < n; ++i)
      if (primary.did_hit[i]) scratch->sky_E[i] = ctx.sky->Irradiance(scratch->n_s[i]);
    return;
  }
  SkyIrradianceVolume::ShBlend blend;
  auto shared = [&](int, int, const int* quad) {
    const int i00 = quad[0];
    // the transport's rule (render/transport/realtime_shading.h) over the tile's hits.
    struct {
      const PrimaryHits* primary;
      const int* quad;
      bool Hit(int c) const { return primary->did_hit[quad[c]]; }
      int Geom(int c) const { return primary->hits[quad[c]].geom; }
      void Ng(int c, float ng[3]) const {
        for (int a = 0; a < 3; ++a) ng[a] = primary->hits[quad[c]].ng_W[a];
      }
      void P(int c, float p[3]) const {
        for (int a = 0; a < 3; ++a) p[a] = primary->hits[quad[c]].p_W[a];
      }
    } q{&primary, quad};
    float m[3];
    if (!cuda::SkyQuadSharesBlend(q, volume->spacing(), m)) return false;
    const Eigen::Vector3f mean(m[0], m[1], m[2]);
    const Eigen::Vector3f& n0 = primary.hits[i00].ng_W;
    volume->Blend(mean, n0, &blend);
    // IrradianceAt is a function of the blend and the normal: pixels whose shading normals are
    // bitwise equal to the first's (a flat face without a normal map: every quad of the default
    // room) take its value instead of evaluating the SH again.
    const Eigen::Vector3f& ns0 = scratch->n_s[i00];
    const Eigen::Vector3f E0 = volume->IrradianceAt(blend, ns0, *ctx.sky);
    scratch->sky_E[i00] = E0;
    for (int c = 1; c < 4; ++c) {
      const Eigen::Vector3f& ns = scratch->n_s[quad[c]];
      scratch->sky_E[quad[c]] = std::memcmp(ns.data(), ns0.data(), sizeof(float) * 3) == 0
                                    ? E0
                                    : volume->IrradianceAt(blend, ns, *ctx.sky);
    }
    return true;
  };
  auto single = [&](int i) {
    if (!primary.did_hit[i]) return;
    volume->Blend(primary.hits[i].p_W, primary.hits[i].ng_W, &blend);
    scratch->sky_E[i] = volume->IrradianceAt(blend, scratch->n_s[i], *ctx.sky);
  };
  ForEachQuad(primary.tile, shared, single);
}

// what the effects do to the radiance L seen through pixel `pixel` along the camera ray:
// the media along the ray attenuate and add to it, and the nearest particle streak is
// alpha-composited over it (render/media/media_realtime.h, render/particles/particle_streaks.h). no
// random numbers here (the froxel volumes are jittered per column when they are built). `quad`: the
// shared froxel lookups of the pixel's 2x2 quad, or null.
Eigen::Vector3f ApplyViewEffects(const FrameContext& ctx, const Ray& ray, bool hit, float t_hit,
                                 int u, int v, Eigen::Vector3f L, const MediaQuad* quad) {
  const MediaFrame& fx = *ctx.effects;
  const RealtimeMedia* rm = fx.realtime_media();
  const ParticleScene* parts = fx.particles();
  if (rm == nullptr && parts == nullptr) return L;
  const float d_len = ray.d.norm();
  const Eigen::Vector3f d = ray.d / d_len;
  const float inf = std::numeric_limits<float>::infinity();
  const float t_end = hit ? t_hit * d_len : inf;
  if (rm != nullptr) {
    const MediaSegment seg = rm->IntegrateView(*ctx.lights, ray.o, d, t_end, u, v, quad);
    L = seg.T.cwiseProduct(L) + seg.L_add;
  }
  ParticleHit ph;
  if (parts != nullptr && parts->PixelHit(ray, u, v, hit ? t_hit : inf, &ph)) {
    // the streak over what lies behind it: alpha (media to the streak, then the streak) +
    // (1 - alpha) (media to the end, then the surface); equal to compositing at the streak.
    const float t_p = ph.t * d_len;
    Eigen::Vector3f Lp = parts->Shade(ph, ray.o + t_p * d, *ctx.lights, fx.sky_ambient());
    if (rm != nullptr) {
      const MediaSegment front = rm->IntegrateView(*ctx.lights, ray.o, d, t_p, u, v, quad);
      Lp = front.T.cwiseProduct(Lp) + front.L_add;
    }
    for (int c = 0; c < 3; ++c) L[c] = StreakOver(ph.alpha, Lp[c], L[c]);
  }
  return L;
}

// the effects on every pixel of a tile whose radiance buffer holds its final surface or sky
// radiance, per 2x2 quad: a full quad whose pixels all hit a surface or all see the sky shares
// one set of froxel lookups (RealtimeMedia::PrepareQuad at the mean distance of its pixels);
// other pixels look the froxels up themselves.
void ApplyTileViewEffects(const FrameContext& ctx, const PrimaryHits& primary,
                          const FrameBuffers& out) {
  const PixelTile& tile = primary.tile;
  const RealtimeMedia* rm = ctx.effects->realtime_media();
  auto apply = [&](int i, const MediaQuad* quad) {
    const int u = tile.x0 + i % tile.width, v = tile.y0 + i / tile.width;
    float* Lp = out.radiance->at(u, v);
    const Eigen::Vector3f Lf =
        ApplyViewEffects(ctx, primary.rays[i], primary.did_hit[i], primary.hits[i].t, u, v,
                         Eigen::Vector3f(Lp[0], Lp[1], Lp[2]), quad);
    Lp[0] = Lf.x(), Lp[1] = Lf.y(), Lp[2] = Lf.z();
  };
  auto shared = [&](int x, int y, const int* quad) {
    if (rm == nullptr) return false;
    const int i00 = quad[0];
    for (int c = 1; c < 4; ++c)
      if (primary.did_hit[quad[c]] != primary.did_hit[i00]) return false;
    float t_c = std::numeric_limits<float>::infinity();
    if (primary.did_hit[i00]) {
      t_c = 0;
      for (int c = 0; c < 4; ++c)
        t_c += 0.25f * primary.hits[quad[c]].t * primary.rays[quad[c]].d.norm();
    }
    Eigen::Vector3f d_c = Eigen::Vector3f::Zero();
    for (int c = 0; c < 4; ++c) d_c += primary.rays[quad[c]].d.normalized();
    MediaQuad q;
    rm->PrepareQuad(tile.x0 + x, tile.y0 + y, t_c, primary.rays[i00].o, d_c.normalized(), &q);
    for (int c = 0; c < 4; ++c) apply(quad[c], &q);
    return true;
  };
  ForEachQuad(tile, shared, [&](int i) { apply(i, nullptr); });
}

}  // namespace

int64_t RealtimeIntegrator::RenderTile(const FrameContext& ctx, const PrimaryHits& primary,
                                       const FrameBuffers& out) const {
  thread_local Scratch scratch;
  const PixelTile& tile = primary.tile;
  const int n = tile.width * tile.height;
  const int num_lights = ctx.lights->size();
  scratch.samples.resize(num_lights);
  scratch.contrib.resize(num_lights);
  scratch.area_c.resize(static_cast<size_t>(num_lights) * n);
  scratch.area_vis.assign(static_cast<size_t>(num_lights) * n, -1);
  scratch.area_seen.assign(num_lights, 0);
  TileSkyIrradiance(ctx, primary, &scratch);
  scratch.mirror.assign(n, 0.0f);
  scratch.total.resize(n);
  bool any_mirror = false;
  static const RenderAblation kAllOn;
  const RenderAblation& ablation = ctx.ablation != nullptr ? *ctx.ablation : kAllOn;
  int64_t traced = 0;
  const MediaFrame* fx = ctx.effects;
  const RealtimeMedia* rm = fx != nullptr ? fx->realtime_media() : nullptr;
  const float wetness = fx != nullptr ? fx->surface_wetness() : 0.0f;
  const float spread = ctx.camera->pixel_spread_rad();

  // runs of kLanes pixels (a full tile row): per-pixel set-up (materials, textures, sky,
  // random numbers), then the BRDF coefficients, the ambient term and every light for all
  // lanes at once, the shadow rays towards one light as one Embree packet.
  for (int i0 = 0; i0 < n; i0 += kLanes) {
    const int m = std::min(kLanes, n - i0);
    // pixel coordinates of the lanes (idle lanes repeat the last pixel), stepped along the
    // tile's rows: one division per run instead of one per pixel.
    int lane_u[kLanes], lane_v[kLanes];
    {
      int x = i0 % tile.width, y = i0 / tile.width;
      for (int k = 0; k < kLanes; ++k) {
        lane_u[k] = tile.x0 + x, lane_v[k] = tile.y0 + y;
        if (k + 1 < m && ++x == tile.width) x = 0, ++y;
      }
    }
    LaneMask hit = LaneMask::Constant(false);
    BsdfLanes bsdf;
    PbrLanes pbr;
    Vec3Lanes p, origin, L, emission, sky_E;
    for (int k = 0; k < kLanes; ++k) {
      const int i = i0 + k;
      const bool lane_hit = k < m && primary.did_hit[i];
      hit[k] = lane_hit;
      if (!lane_hit) {
        // harmless values for idle lanes: every lane computes every light.
        const Eigen::Vector3f z = Eigen::Vector3f::UnitZ();
        const Eigen::Vector3f zero = Eigen::Vector3f::Zero();
        p.Set(k, zero), origin.Set(k, zero), emission.Set(k, zero), sky_E.Set(k, zero);
        bsdf.SetFrame(k, z, z, z);
        pbr.base_color.Set(k, zero);
        pbr.roughness[k] = 1, pbr.metallic[k] = 0, pbr.specular[k] = 0;
        if (k < m) {
          const int u = lane_u[k], v = lane_v[k];
          const Eigen::Vector3f sky = ctx.sky->Background(primary.rays[i].d.normalized());
          float* Lp = out.radiance->at(u, v);
          Lp[0] = sky.x(), Lp[1] = sky.y(), Lp[2] = sky.z();
          if (out.albedo) std::fill_n(out.albedo->at(u, v), 3, 0.0f);
          if (out.normal) std::fill_n(out.normal->at(u, v), 3, 0.0f);
        }
        continue;
      }
      const int u = lane_u[k], v = lane_v[k];
      const SurfaceHit& h = primary.hits[i];
      const Eigen::Vector3f& wo = scratch.wo[i];
      // the texture is filtered over the pixel's ray cone where it meets the surface.
      SurfaceMaterial mat =
          primary.materials != nullptr
              ? primary.materials[i]
              : ctx.materials->Evaluate(
                    h, ConeFootprint(spread, h.t * primary.rays[i].d.norm(), -wo, h));
      if (wetness > 0) ApplySurfaceWetness(wetness, h.ns_W, &mat.pbr);
      const Eigen::Vector3f& n_s = scratch.n_s[i];
      bsdf.SetFrame(k, n_s, h.ng_W, wo);
      pbr.Set(k, mat.pbr);
      if (mat.mirror > 0 && ablation.mirror) scratch.mirror[i] = mat.mirror, any_mirror = true;
      emission.Set(k, mat.emission);
      p.Set(k, h.p_W);
      // shadow rays start off the surface on the lit side (lights behind it contribute 0).
      origin.Set(k, OffsetRayOrigin(h.p_W, h.ng_W));
      sky_E.Set(k, mat.occlusion * scratch.sky_E[i]);

      if (out.albedo) {
        float* a = out.albedo->at(u, v);
        a[0] = mat.pbr.base_color.x(), a[1] = mat.pbr.base_color.y(), a[2] = mat.pbr.base_color.z();
      }
      if (out.normal) {
        float* nn = out.normal->at(u, v);
        nn[0] = n_s.x(), nn[1] = n_s.y(), nn[2] = n_s.z();
      }
    }
    if (!hit.any()) continue;
    // the lattice point of every lane's pixel (render/light/lamp_math.h): where its shadow rays
    // towards lights with an extent go. no random numbers.
    Lanes stratum_u1, stratum_u2;
    for (int k = 0; k < kLanes; ++k)
      LightStratumUniforms(kPenumbraRays * LightStratum(lane_u[k], lane_v[k]),
                           kLightStrata * kPenumbraRays, &stratum_u1[k], &stratum_u2[k]);
    bsdf.SetCoefficients(pbr);

    // emission and sky ambient, E_sky / pi (c_diff (1 - S) + S).
    L = cuda::AmbientRadiance<Lanes, Vec3Lanes>(emission, sky_E, bsdf.c_diff, bsdf.f0, bsdf.n_v,
                                                pbr.roughness);

    // where the surface points lie in the media's light volume (shared by all lights).
    float vol_T[kLanes][kMaxVolumeLights];
    bool located[kLanes] = {};
    if (rm != nullptr)
      for (int k = 0; k < kLanes; ++k)
        located[k] = hit[k] && rm->LightTransmittances(p.Lane(k), vol_T[k]);
    // one sample per light; the unshadowed total decides which shadow rays are worth tracing.
    Lanes total = LuminanceLanes(L);
    for (int j = 0; j < num_lights; ++j) {
      LightSampleLanes& s = scratch.samples[j];
      Vec3Lanes& c = scratch.contrib[j];
      const LightPod& light = ctx.lights->pods()[j];
      const bool extended = cuda::IsExtendedLightPod(light);
      cuda::ExtendedLightAxis<Lanes, Vec3Lanes, LaneMask> axis;
      if (extended) {
        axis = cuda::ExtendedLightAxisOf<Lanes, Vec3Lanes, LaneMask>(light, p, bsdf.n);
        // every hit lane below the light's horizon (e.g. a run of a wall facing away from a
        // lamp): the contribution is exactly 0 in every lane, so the light's sample, BRDF and
        // media terms are skipped (nothing reads them where c is 0) and the total stays as it is.
        if (!(hit && axis.reaches).any()) {
          c = Vec3Lanes{Lanes::Zero(), Lanes::Zero(), Lanes::Zero()};
          continue;
        }
      }
      ctx.lights->SampleLanes(j, p, stratum_u1, stratum_u2, &s);
      const LaneMask on = hit && s.valid;
      // the transport's arithmetic (render/transport/realtime_shading.h), over the lanes.
      if (extended) {
        c = cuda::ExtendedLightContribution(axis, bsdf.n, bsdf.ng, bsdf.wo, bsdf.n_v, bsdf.c_diff,
                                            bsdf.f0, bsdf.a2, on, s.E, &s.wi, &s.distance);
      } else {
        c = cuda::PointLightContribution<Lanes, Vec3Lanes, LaneMask>(
            bsdf.n, bsdf.ng, bsdf.wo, bsdf.n_v, bsdf.c_diff, bsdf.f0, bsdf.a2, on, s.E, s.wi);
      }
      if (rm != nullptr) {
        // attenuation of the light by the media between the surface and the light.
        for (int k = 0; k < kLanes; ++k) {
          // lanes the light does not reach (behind the surface, outside its cone) stay 0.
          if (!(hit[k] && s.valid[k]) || (c.x[k] == 0 && c.y[k] == 0 && c.z[k] == 0)) continue;
          if (located[k] && j < rm->num_volume_lights()) {
            const float T = vol_T[k][j];
            c.x[k] *= T, c.y[k] *= T, c.z[k] *= T;
            continue;
          }
          const Eigen::Vector3f T =
              rm->LightTransmittance(j, p.Lane(k), s.wi.Lane(k), s.distance[k]);
          c.x[k] *= T.x(), c.y[k] *= T.y(), c.z[k] *= T.z();
        }
      }
      total += LuminanceLanes(c);
    }
    for (int k = 0; k < m; ++k) scratch.total[i0 + k] = total[k];
    // lights in order: negligible or shadowless contributions are added as they are, the
    // others after one packet of shadow rays.
    for (int j = 0; j < num_lights; ++j) {
      const Vec3Lanes& c = scratch.contrib[j];
      const LaneMask lit = GreaterThan(LuminanceLanes(c), 0.0f);
      if (!lit.any()) continue;
      const LaneMask shadowed =
          ctx.lights->lights()[j].cast_shadow && ablation.shadows
              ? lit && cuda::ShadowRayWorthTracing<Lanes, LaneMask>(LuminanceLanes(c), total)
              : LaneMask::Constant(false);
      const LaneMask unshadowed = lit && !shadowed;
      L = L + Where(unshadowed, c);
      if (!shadowed.any()) continue;
      const LightSampleLanes& s = scratch.samples[j];
      const bool extended = IsExtendedLight(ctx, j);
      const Lanes tmax = s.distance * (1.0f - 1e-4f);  // +inf stays +inf
      // the sun's rays that a static box provably blocks are occluded without tracing them.
      const LaneMask skipped = ctx.sun_occluders != nullptr && j == ctx.sun_occluders->light_index()
                                   ? ctx.sun_occluders->BlocksLanes(origin, s.wi, shadowed)
                                   : LaneMask::Constant(false);
      const LaneMask to_trace = shadowed && !skipped;
      LaneMask occluded;
      if (to_trace.any()) ctx.scene->OccludedLanes(origin, s.wi, tmax, to_trace, &occluded);
      traced += to_trace.count();
      if (extended) {
        // the verdict waits for its neighbours' (ResolveSharedVisibility); a lane the sun-occluder
        // map skipped is occluded (the map's verdict is exact for that ray).
        const size_t base = static_cast<size_t>(j) * n + static_cast<size_t>(i0);
        uint8_t seen = 0;
        for (int k = 0; k < m; ++k) {
          if (!shadowed[k]) continue;
          const int8_t v = skipped[k] || occluded[k] ? 0 : 1;
          scratch.area_vis[base + k] = v;
          seen |= static_cast<uint8_t>(1 + v);
          scratch.area_c[base + k] = Eigen::Vector3f(c.x[k], c.y[k], c.z[k]);
        }
        scratch.area_seen[j] |= seen;
        continue;
      }
      const LaneMask visible = to_trace && !occluded;
      L = L + Where(visible, c);
    }
    for (int k = 0; k < m; ++k) {
      if (!hit[k]) continue;
      float* Lp = out.radiance->at(lane_u[k], lane_v[k]);
      Lp[0] = L.x[k], Lp[1] = L.y[k], Lp[2] = L.z[k];
    }
  }
  // the shadowed light of lights with an extent, its visibility shared between neighbours.
  ResolveSharedVisibility(ctx, primary, scratch, out, &traced);
  // the mirror layer once every pixel holds its own radiance (render/cpu/mirror_layer.h).
  if (any_mirror) traced += ShadeMirrorLayerTile(ctx, primary, scratch.mirror.data(), wetness, out);
  // the effects once every pixel of the tile holds its surface or sky radiance.
  if (fx != nullptr) ApplyTileViewEffects(ctx, primary, out);
  return traced;
}

}  // namespace penumbra
