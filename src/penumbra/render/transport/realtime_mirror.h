#pragma once
// the realtime tier's mirror layer (SurfaceMaterial::mirror, weight r: L becomes (1 - r) L +
// r L_m), written once: the mirrored view ray (MirroredRay), the shading of its hit with one
// random sample of every light and a shadow ray (MirrorHitRadiance), the grid pixels an
// off-grid layer pixel borrows L_m from (MirrorGridLenders, render/light/mirror_math.h) and the
// blend (MirrorGridMean, MirrorLayerBlend). the backends drive them: render/cpu/mirror_layer.cc
// per 16x16 tile over Embree, the kernels of render/cuda per pixel over the BVH in three steps
// (TraceMirrorRay, ShadeMirrorHit, ApplyMirrorLayer). a backend's tracer and its surface
// evaluation reach the shared functions as a shading point and an `occluded` callable.

#include <cstdint>

#include "penumbra/core/host_device.h"
#include "penumbra/core/rng.h"
#include "penumbra/render/bvh/bvh_traversal.h"
#include "penumbra/render/light/brdf_math.h"
#include "penumbra/render/light/light_math.h"
#include "penumbra/render/light/mirror_math.h"
#include "penumbra/render/transport/realtime_shading.h"
#include "penumbra/render/transport/scene_view.h"
#include "penumbra/render/transport/surface.h"

namespace penumbra::cuda {

/// the mirrored ray off a mirror layer: the unit view direction d reflected about the unit
/// geometric normal ng, d - 2 (d . ng) ng, from the hit point p pushed off the surface on that
/// side (render/ray.h's SpawnRay); tmin 0, tmax +inf.
PB_HOST_DEVICE inline TraceRay MirroredRay(const Float3& d, const Float3& p, const Float3& ng) {
  const float k = 2.0f * pbm::Dot<float>(d, ng);
  const Float3 wi{d.x - k * ng.x, d.y - k * ng.y, d.z - k * ng.z};
  const float side = pbm::Dot<float>(wi, ng) >= 0 ? 1.0f : -1.0f;
  TraceRay r;
  r.o = OffsetOrigin(p, Float3{side * ng.x, side * ng.y, side * ng.z});
  r.d = ToF3(wi);
  r.tmin = 0;
  r.tmax = INFINITY;
  return r;
}

/// the reflected radiance L_m where a mirrored ray hits the surface sp (sp.n: the usable
/// shading normal; sp.wo: unit, back along the ray): its emission, its ambient term
/// E_sky / pi occlusion (c_diff (1 - S) + S) with `sky` the occluded sky irradiance on sp.n and
/// S the split-sum fit (EnvBrdfApprox), and one sample of each of the num_lights `lights`
/// (random numbers: draws num_lights + j of `stream`) through the BRDF (BrdfEvalWorld), with a
/// shadow ray (from OffsetOrigin(sp.p, sp.ng), ShadowRayOf's tmax) where `shadows` and the
/// light casts shadows: a light counts unless occluded(j, ray) says the ray is blocked. one
/// reflection: a mirror seen in a mirror shows its BRDF only.
template <class Occluded>
PB_HOST_DEVICE inline Float3 MirrorHitRadiance(const ShadingPoint& sp, const Float3& sky,
                                               const LightPod* lights, int num_lights,
                                               uint64_t stream, bool shadows, Occluded&& occluded) {
  const Float3& p = sp.p;
  const Float3& ng = sp.ng;
  const Float3& n = sp.n;
  const Float3& wo = sp.wo;
  Float3 c_diff, f0;
  float alpha;
  BrdfCoefficientsOf<float, Float3>(sp.base, sp.roughness, sp.metallic, sp.specular, &c_diff, &f0,
                                    &alpha);
  const float a2 = alpha * alpha;
  const float n_v = pbm::Dot<float>(n, wo);
  const Float3 spec =
      EnvBrdfApprox<float, Float3>(f0, pbm::Max(n_v, 0.0f), pbm::Clamp(sp.roughness, 0.0f, 1.0f));
  const Float3 reflect{c_diff.x * (1.0f - spec.x) + spec.x, c_diff.y * (1.0f - spec.y) + spec.y,
                       c_diff.z * (1.0f - spec.z) + spec.z};
  const float k = pbm::kInvPi * sp.occlusion;
  Float3 L{sp.emission.x + (sky.x * k) * reflect.x, sp.emission.y + (sky.y * k) * reflect.y,
           sp.emission.z + (sky.z * k) * reflect.z};
  TraceRay sr;
  sr.o = OffsetOrigin(p, ng);
  sr.tmin = 0;
  const uint64_t first_draw = static_cast<uint64_t>(num_lights);
  for (int j = 0; j < num_lights; ++j) {
    float u1, u2;
    Rng::Uniform2Of(Rng::DrawAt(stream, first_draw + static_cast<uint64_t>(j)), &u1, &u2);
    Float3 wi, E;
    float dist;
    bool valid;
    SampleLight<float, Float3, bool>(lights[j], p, u1, u2, &wi, &dist, &E, &valid);
    if (!valid) continue;
    const Float3 fr = BrdfEvalWorld<float, Float3>(n, ng, wo, n_v, c_diff, f0, a2, wi);
    const Float3 c{fr.x * E.x, fr.y * E.y, fr.z * E.z};
    if (!(pbm::Max(pbm::Max(c.x, c.y), c.z) > 0)) continue;
    if (shadows && lights[j].cast_shadow != 0) {
      sr.d = ToF3(wi);
      sr.tmax = dist * (1.0f - 1e-4f);  // +inf stays +inf
      if (occluded(j, sr)) continue;
    }
    L = L + c;
  }
  return L;
}

/// the traced grid pixels whose reflected radiance a layer pixel at (x, y) of a tile_w x tile_h
/// tile takes when it is off its layer's grid of step s (MirrorGridStep): of the up to 4 grid
/// pixels around it in the tile, those for which lends(x', y') says they hold a traced L_m of a
/// layer with the same step on the same flat face (same geom, equal geometric normal), in the
/// order v, then u; their tile coordinates in lx, ly and bilinear weights (MirrorGridWeight) in
/// w. returns how many (0: the pixel traces its own ray). tiles start at multiples of the grid
/// steps, so a tile's grid is the image's.
template <class Lends>
PB_HOST_DEVICE inline int MirrorGridLenders(int x, int y, int s, int tile_w, int tile_h,
                                            Lends&& lends, int lx[4], int ly[4], float w[4]) {
  const int gx = x - x % s, gy = y - y % s;
  const int xs[2] = {gx, gx + s}, ys[2] = {gy, gy + s};
  const float wx[2] = {MirrorGridWeight(x % s, s, 0), MirrorGridWeight(x % s, s, 1)};
  const float wy[2] = {MirrorGridWeight(y % s, s, 0), MirrorGridWeight(y % s, s, 1)};
  int count = 0;
  for (int b = 0; b < 2; ++b) {
    if (!(wy[b] > 0) || ys[b] >= tile_h) continue;
    for (int a = 0; a < 2; ++a) {
      if (!(wx[a] > 0) || xs[a] >= tile_w) continue;
      if (!lends(xs[a], ys[b])) continue;
      lx[count] = xs[a];
      ly[count] = ys[b];
      w[count] = wx[a] * wy[b];
      ++count;
    }
  }
  return count;
}

/// the reflected radiance of an off-grid layer pixel: the weighted mean of its `count` (> 0)
/// lenders' L_m (MirrorGridLenders' weights w; lent(k): lender k's L_m), renormalised over them.
template <class Lent>
PB_HOST_DEVICE inline Float3 MirrorGridMean(int count, const float w[4], Lent&& lent) {
  Float3 acc{0, 0, 0};
  float wsum = 0;
  for (int k = 0; k < count; ++k) {
    acc = acc + w[k] * lent(k);
    wsum += w[k];
  }
  return Float3{acc.x / wsum, acc.y / wsum, acc.z / wsum};
}

/// a layer pixel's radiance: its own radiance L blended with its reflected radiance Lm,
/// (1 - r) L + r Lm per channel (MirrorBlend).
PB_HOST_DEVICE inline Float3 MirrorLayerBlend(const Float3& L, const Float3& Lm, float r) {
  return Float3{MirrorBlend(L.x, Lm.x, r), MirrorBlend(L.y, Lm.y, r), MirrorBlend(L.z, Lm.z, r)};
}

/// the mirrored view ray of pixel (u, v), whose primary geometry f.geometry holds a hit: the
/// unit primary direction d reflected about the geometric normal, d - 2 (d . ng) ng, from the
/// hit pushed off the surface on that side (render/ray.h's SpawnRay); *path_m: the
/// camera-to-hit distance (the texture cone's length before the ray).
PB_HOST_DEVICE inline TraceRay MirrorRay(const RealtimeFrameView& f, int u, int v, float* path_m) {
  const int64_t i = static_cast<int64_t>(v) * f.camera.width + u;
  const PixelGeometry& g = f.geometry[i];
  const TraceRay pr = PrimaryRay(f.camera, u, v);
  const float d_len = sqrtf(pr.d.x * pr.d.x + pr.d.y * pr.d.y + pr.d.z * pr.d.z);
  const Float3 d{pr.d.x / d_len, pr.d.y / d_len, pr.d.z / d_len};
  const Float3& p = g.p_or_d;
  const TraceRay r = MirroredRay(d, p, g.ng);
  const Float3 to_cam{p.x - pr.o.x, p.y - pr.o.y, p.z - pr.o.z};
  *path_m = sqrtf(pbm::Dot<float>(to_cam, to_cam));
  return r;
}

/// the traced grid pixels whose reflected radiance pixel (u, v) of the mirror layer takes when
/// it is off its layer's grid: MirrorGridLenders in its 16x16 tile (ShadowTileOf), a grid pixel
/// lending where its layer has the same step; their pixel indices in idx and bilinear weights
/// in w. returns how many (0: the pixel traces its own ray).
PB_HOST_DEVICE inline int MirrorGridNeighbours(const RealtimeFrameView& f, int u, int v,
                                               int64_t idx[4], float w[4]) {
  const int W = f.camera.width, H = f.camera.height;
  const PixelGeometry& gi = f.geometry[static_cast<int64_t>(v) * W + u];
  const int s = MirrorGridStep(gi.mirror);
  const ShadowTile tile = ShadowTileOf(u, v, W, H);
  auto at = [&](int x, int y) { return static_cast<int64_t>(tile.y0 + y) * W + tile.x0 + x; };
  // a grid pixel of a layer with this step traces its own ray.
  auto lends = [&](int x, int y) {
    const PixelGeometry& gj = f.geometry[at(x, y)];
    if (!(gj.mirror > 0) || MirrorGridStep(gj.mirror) != s) return false;
    return gj.geom == gi.geom && gj.ng.x == gi.ng.x && gj.ng.y == gi.ng.y && gj.ng.z == gi.ng.z;
  };
  int lx[4], ly[4];
  const int count =
      MirrorGridLenders(u - tile.x0, v - tile.y0, s, tile.width, tile.height, lends, lx, ly, w);
  for (int k = 0; k < count; ++k) idx[k] = at(lx[k], ly[k]);
  return count;
}

/// whether pixel (u, v) traces its own mirrored ray: its surface has a mirror layer and the
/// pixel lies on the layer's grid, or no grid pixel around it can lend it theirs.
PB_HOST_DEVICE inline bool MirrorTraces(const RealtimeFrameView& f, int u, int v) {
  const int W = f.camera.width;
  const float r = f.geometry[static_cast<int64_t>(v) * W + u].mirror;
  if (!(r > 0)) return false;
  const int s = MirrorGridStep(r);
  if ((u % kShadowTileSize) % s == 0 && (v % kShadowTileSize) % s == 0) return true;
  int64_t idx[4];
  float w[4];
  return MirrorGridNeighbours(f, u, v, idx, w) == 0;
}

/// the mirror layer, step 1 of 3 (after PrimaryGeometry at every pixel): where pixel (u, v)
/// traces (MirrorTraces), its mirrored ray's closest hit (f.mirror_hits) and geometry for the
/// host's sky pass (f.mirror_geometry; hit -1 where it traces none).
PB_HOST_DEVICE inline void TraceMirrorRay(const RealtimeFrameView& f, int u, int v) {
  const int64_t i = static_cast<int64_t>(v) * f.camera.width + u;
  PixelGeometry g;
  g.hit = -1;
  if (!MirrorTraces(f, u, v)) {
    f.mirror_geometry[i] = g;
    return;
  }
  float path_m;
  const TraceRay r = MirrorRay(f, u, v, &path_m);
  TraceHit h;
  TraceClosest(f.scene, r, &h);
  f.mirror_hits[i] = h;
  const float d_len = sqrtf(r.d.x * r.d.x + r.d.y * r.d.y + r.d.z * r.d.z);
  if (h.instance < 0) {
    g.hit = 0;
    g.p_or_d = Float3{r.d.x / d_len, r.d.y / d_len, r.d.z / d_len};
  } else {
    const ShadingPoint sp = EvaluateSurface(f, r, h, d_len, path_m);
    g.hit = 1;
    g.geom = f.scene.records[f.scene.prims[h.prim].record].geom;
    g.p_or_d = sp.p;
    g.ng = sp.ng;
    g.ns = sp.n;
  }
  f.mirror_geometry[i] = g;
}

/// the mirror layer, step 2 of 3 (after the host's mirror sky terms): the reflected radiance
/// L_m of a pixel that traced a mirrored ray (f.mirror_radiance): the sky's where it escapes,
/// else MirrorHitRadiance at its hit (random numbers from the pixel's stream 0,
/// FrameContext::PixelStream), its shadow rays traced through the BVH.
PB_HOST_DEVICE inline void ShadeMirrorHit(const RealtimeFrameView& f, int u, int v) {
  const int64_t i = static_cast<int64_t>(v) * f.camera.width + u;
  if (f.mirror_geometry[i].hit < 0) return;
  const Float3 sky = f.mirror_sky[i];
  const TraceHit h = f.mirror_hits[i];
  if (h.instance < 0) {
    f.mirror_radiance[i] = sky;
    return;
  }
  float path_m;
  const TraceRay r = MirrorRay(f, u, v, &path_m);
  const float d_len = sqrtf(r.d.x * r.d.x + r.d.y * r.d.y + r.d.z * r.d.z);
  const ShadingPoint sp = EvaluateSurface(f, r, h, d_len, path_m);
  const uint64_t pixel =
      static_cast<uint64_t>(v) * static_cast<uint64_t>(f.camera.width) + static_cast<uint64_t>(u);
  const uint64_t stream = HashKeys(HashKeys(f.frame_key, pixel), uint64_t{0});
  f.mirror_radiance[i] =
      MirrorHitRadiance(sp, sky, f.lights, f.num_lights, stream, true,
                        [&](int, const TraceRay& sr) { return TraceOccluded(f.scene, sr); });
}

/// the mirror layer, step 3 of 3 (after ShadeMirrorHit at every pixel, and after the shared
/// visibility): pixel (u, v)'s radiance L blended with its reflected radiance L_m,
/// (1 - r) L + r L_m (MirrorBlend), L_m its own or the MirrorGridNeighbours' weighted mean;
/// L unchanged where its surface has no mirror layer.
PB_HOST_DEVICE inline Float3 ApplyMirrorLayer(const RealtimeFrameView& f, int u, int v, Float3 L) {
  const int64_t i = static_cast<int64_t>(v) * f.camera.width + u;
  const float r = f.geometry[i].mirror;
  if (!(r > 0)) return L;
  Float3 Lm;
  if (f.mirror_geometry[i].hit >= 0) {
    Lm = f.mirror_radiance[i];
  } else {
    int64_t idx[4];
    float w[4];
    const int count = MirrorGridNeighbours(f, u, v, idx, w);
    Lm = MirrorGridMean(count, w, [&](int k) { return f.mirror_radiance[idx[k]]; });
  }
  return MirrorLayerBlend(L, Lm, r);
}

}  // namespace penumbra::cuda
