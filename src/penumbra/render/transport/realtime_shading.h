#pragma once
// the realtime tier's surface loop, per pixel, as PB_HOST_DEVICE functions over plain data
// (RealtimeFrameView): the kernels of render/cuda run them on the GPU and RealtimeHostRenderer
// (render/cuda/realtime_frame.h) on the CPU. the model:
//
// them as render/cpu/realtime_integrator.cc does:
//
//   L = Le + E_sky / pi (c_diff (1 - S) + S) + sum over lights f(wo, wi) |n . wi| E_i V_i
//
// with the same lattice points per pixel (render/light/lamp_math.h: LightStratum, no random
// numbers), lamps and the sun's disc in the same closed form (ExtendedLightShading) and their
// visibility V_i shared between neighbouring pixels as the CPU shares it
// (render/light/shadow_window_math.h: the ratio estimator of Heitz et al. 2018 over each pixel's
// 5x5 same-surface window, cut at the 16x16 tiles' edges; SharedVisibilityRays / Fraction / Resolve
// after ShadeRealtimePixel), the same negligible-light rule (no shadow ray below
// kGpuNegligibleLight of the unshadowed total) and shadow rays from OffsetRayOrigin. E_sky
// (occluded sky irradiance on the surface normal, one probe blend per flat 2x2 quad as the CPU) and
// the sky radiance of rays that escape come per pixel from QuadSkyTerms, the shared lookups of
// render/sky/sky_eval_math.h that SkyModel and SkyIrradianceVolume call on the CPU (a kernel of
// their own, or the host's RealtimeFrameData::SkyTerms). the mirror layer (SurfaceMaterial::mirror,
// weight r: L becomes (1 - r) L + r L_m) as render/cpu/mirror_layer.cc: the mirrored view ray
// traced on the layer's grid (render/light/mirror_math.h; TraceMirrorRay), its hit shaded with one
// random sample of every light and a shadow ray and the occluded sky irradiance at the hit
// (MirrorSkyTerm, beside the primary sky terms; ShadeMirrorHit), the other layer pixels
// interpolated from the grid and blended (ApplyMirrorLayer). the lighting effects reach it as the
// CPU's: the lights (scaled, extra) and the sky (moved sun, scaled) through the frame's data, the
// surface wetness in EvaluateSurface (render/material/wetness_math.h). meshes and height fields
// shade with their vertex normals mixed at the hit and map their textures by their texcoords
// (HitShadingNormal, HitTexcoords: primary_pixel.h), escaping rays see the MJCF

#include <cstdint>

#include "penumbra/core/host_device.h"
#include "penumbra/core/rng.h"
#include "penumbra/render/bvh/bvh_traversal.h"
#include "penumbra/render/light/lamp_math.h"
#include "penumbra/render/light/light_math.h"
#include "penumbra/render/light/shadow_window_math.h"
#include "penumbra/render/media/media_realtime_math.h"
#include "penumbra/render/shading_math.h"
#include "penumbra/render/sky/sky_eval_math.h"
#include "penumbra/render/transport/scene_view.h"
#include "penumbra/render/transport/surface.h"

namespace penumbra::cuda {

/// whether light l has an extent: a sphere lamp (radius > 0) or the sun's disc (as the CPU
/// realtime integrator's IsExtendedLight).
PB_HOST_DEVICE inline bool IsExtendedLightPod(const LightPod& l) {
  return HasLightExtent(l.kind == LightKind::kDirectional, l.cos_angular_radius, l.radius_m);
}

/// the two uniform numbers of lattice point r (0 <= r < kLightPenumbraRays) of pixel (u, v):
/// point kLightPenumbraRays LightStratum(u, v) + r of the kLightStrata kLightPenumbraRays
/// lattice (render/light/lamp_math.h), as RealtimeIntegrator takes them.
PB_HOST_DEVICE inline void PixelLatticeUniforms(int u, int v, int r, float* u1, float* u2) {
  LightStratumUniforms(kLightPenumbraRays * LightStratum(u, v) + r,
                       kLightStrata * kLightPenumbraRays, u1, u2);
}

/// where a light with an extent (IsExtendedLightPod) lies seen from shading point(s) p with
/// unit shading normal n, for a float (one point: the GPU) or Lanes (the CPU's kLanes points;
/// V the 3-vector, M the mask of T): the unit axis w towards its centre, sin^2 sigma of its
/// angular radius, the distance to its near surface (SphereLightAxis's arithmetic; the sun: +inf),
/// cos_t = n . w and sin sigma; where it straddles the horizon (LightStraddlesHorizonOf), and
/// where it may reach the point: above the horizon (cos_t > 1e-6) or straddling it (elsewhere
/// ExtendedLightContribution is exactly 0: scale 0 times a finite BRDF and illuminance).
template <typename T, typename V, typename M>
struct ExtendedLightAxis {
  V w;
  T sin2, dist_near, cos_t, sin_sigma;
  M straddles, reaches;
};

/// ExtendedLightAxis of light l at p (n: the unit shading normal).
template <typename T, typename V, typename M>
PB_HOST_DEVICE inline ExtendedLightAxis<T, V, M> ExtendedLightAxisOf(const LightPod& l, const V& p,
                                                                     const V& n) {
  ExtendedLightAxis<T, V, M> a;
  if (l.kind == LightKind::kDirectional) {
    a.w = V{pbm::Splat<T>(-l.direction_W.x), pbm::Splat<T>(-l.direction_W.y),
            pbm::Splat<T>(-l.direction_W.z)};
    a.sin2 = pbm::Splat<T>(1.0f - l.cos_angular_radius * l.cos_angular_radius);
    a.dist_near = pbm::Splat<T>(INFINITY);
  } else {
    const V t{l.position_W.x - p.x, l.position_W.y - p.y, l.position_W.z - p.z};
    const T d2 = pbm::Dot<T>(t, t);
    const T d = pbm::Sqrt(d2);
    const T inv = pbm::WherePositiveElse(d, T(1.0f / d), 0.0f);
    a.w = V{t.x * inv, t.y * inv, t.z * inv};
    const T r2_d2 = l.radius_m * l.radius_m / d2;
    a.sin2 = pbm::WherePositiveElse(d2, pbm::Min(r2_d2, 1.0f), 1.0f);
    a.dist_near = pbm::Max(T(d - l.radius_m), 0.0f);
  }
  a.cos_t = pbm::Dot<T>(n, a.w);
  a.sin_sigma = pbm::Sqrt(pbm::Max(a.sin2, 0.0f));
  a.straddles = LightStraddlesHorizonOf<T, M>(a.cos_t, a.sin2, a.sin_sigma);
  a.reaches = pbm::GreaterThan(a.cos_t, 1e-6f) || a.straddles;
  return a;
}

/// the unshadowed contribution f(wo, wi) |n . wi| E of a light with an extent with axis `a`
/// (ExtendedLightAxisOf), illuminance E (I / d^2 or E_sun: SampleLight's), where `on`: the BRDF
/// (BrdfEvalWorld: unit shading normal n, geometric normal ng, view direction wo, n_v = n . wo,
/// c_diff, f0, a2 = alpha^2) at the direction to the light's centre, tilted above the horizon
/// where the light straddles it (ExtendedLightShading, lane by lane), times E and the
/// horizon-clipped factor (SphereLightCosine); +0 elsewhere. *wi, *dist: the shadow ray through
/// the point's lattice point (SampleLight's), replaced by the shading direction and the near
/// distance where that point lies below the geometric surface (it would test the surface
/// itself, not the occluders).
template <typename T, typename V, typename M>
PB_HOST_DEVICE inline V ExtendedLightContribution(const ExtendedLightAxis<T, V, M>& a, const V& n,
                                                  const V& ng, const V& wo, const T& n_v,
                                                  const V& c_diff, const V& f0, const T& a2,
                                                  const M& on, const V& E, V* wi, T* dist) {
  V rep = a.w;
  T scale = pbm::Where(on, pbm::StepGreaterThan(a.cos_t, 1e-6f));
  pbm::ForEachLane(on && a.straddles, [&](int k) {
    const float wk[3] = {pbm::LaneOf(a.w.x, k), pbm::LaneOf(a.w.y, k), pbm::LaneOf(a.w.z, k)};
    const float nk[3] = {pbm::LaneOf(n.x, k), pbm::LaneOf(n.y, k), pbm::LaneOf(n.z, k)};
    float r[3];
    pbm::LaneOf(scale, k) = ExtendedLightShading(wk, pbm::LaneOf(a.sin2, k), nk, r);
    pbm::LaneOf(rep.x, k) = r[0], pbm::LaneOf(rep.y, k) = r[1], pbm::LaneOf(rep.z, k) = r[2];
  });
  pbm::ForEachLane(!pbm::GreaterThan(pbm::Dot<T>(ng, *wi), 0.0f), [&](int k) {
    pbm::LaneOf(wi->x, k) = pbm::LaneOf(rep.x, k), pbm::LaneOf(wi->y, k) = pbm::LaneOf(rep.y, k),
                       pbm::LaneOf(wi->z, k) = pbm::LaneOf(rep.z, k);
    pbm::LaneOf(*dist, k) = pbm::LaneOf(a.dist_near, k);
  });
  const V f = BrdfEvalWorld<T, V>(n, ng, wo, n_v, c_diff, f0, a2, rep);
  return V{pbm::Where(on, T(f.x * E.x * scale)), pbm::Where(on, T(f.y * E.y * scale)),
           pbm::Where(on, T(f.z * E.z * scale))};
}

/// the unshadowed contribution f(wo, wi) |n . wi| E of a light without an extent sampled in
/// unit direction wi with illuminance E (SampleLight's), where `on`; +0 elsewhere (the BRDF's
/// arguments as ExtendedLightContribution's).
template <typename T, typename V, typename M>
PB_HOST_DEVICE inline V PointLightContribution(const V& n, const V& ng, const V& wo, const T& n_v,
                                               const V& c_diff, const V& f0, const T& a2,
                                               const M& on, const V& E, const V& wi) {
  const V f = BrdfEvalWorld<T, V>(n, ng, wo, n_v, c_diff, f0, a2, wi);
  return V{pbm::Where(on, T(f.x * E.x)), pbm::Where(on, T(f.y * E.y)),
           pbm::Where(on, T(f.z * E.z))};
}

/// the unshadowed contribution f(wo, wi) |n . wi| E of light j at p for pixel (u, v), as the
/// CPU realtime integrator computes it for its lanes (0 where the light sends nothing): a light
/// without an extent sampled at the pixel's lattice point (PointLightContribution); a lamp or
/// sun disc in closed form (ExtendedLightAxisOf, ExtendedLightContribution). *wi, *dist: the
/// shadow ray of the pixel's first lattice point (the shading direction where that point lies
/// below the geometric surface).
PB_HOST_DEVICE inline Float3 LightContribution(const RealtimeFrameView& f, int j, int u, int v,
                                               const Float3& p, const Float3& n, const Float3& ng,
                                               const Float3& wo, float n_v, const Float3& c_diff,
                                               const Float3& f0, float a2, Float3* wi,
                                               float* dist) {
  float u1, u2;
  PixelLatticeUniforms(u, v, 0, &u1, &u2);
  Float3 E;
  bool valid;
  const LightPod& l = f.lights[j];
  SampleLight<float, Float3, bool>(l, p, u1, u2, wi, dist, &E, &valid);
  if (!valid) return Float3{0, 0, 0};
  if (!IsExtendedLightPod(l))
    return PointLightContribution<float, Float3, bool>(n, ng, wo, n_v, c_diff, f0, a2, true, E,
                                                       *wi);
  const ExtendedLightAxis<float, Float3, bool> a =
      ExtendedLightAxisOf<float, Float3, bool>(l, p, n);
  return ExtendedLightContribution(a, n, ng, wo, n_v, c_diff, f0, a2, true, E, wi, dist);
}

/// the sky term of one pixel from its primary geometry g: SkyBackground (the MJCF skybox, else
/// SkyRadiance) where the ray escapes; where it hits, the occluded sky irradiance (the volume's
/// blend at the point and geometric normal, evaluated at the shading normal; SkyIrradiance of the
/// shading normal outside the grid or with an empty volume).
PB_HOST_DEVICE inline Float3 PixelSkyTerm(const SkyModelPod& sky, const SkyVolumePod& volume,
                                          const PixelGeometry& g) {
  float e[3];
  if (g.hit == 0) {
    // the MJCF skybox where there is one (SkyRadiance without), as the CPU's Background
    SkyBackground(sky, g.p_or_d.x, g.p_or_d.y, g.p_or_d.z, e);
  } else {
    const float ns[3] = {g.ns.x, g.ns.y, g.ns.z};
    if (!volume.empty()) {
      const float p[3] = {g.p_or_d.x, g.p_or_d.y, g.p_or_d.z}, ng[3] = {g.ng.x, g.ng.y, g.ng.z};
      float c[kSkyShStride];
      bool open_sky;
      SkyVolumeBlend(volume, p, ng, c, &open_sky);
      SkyVolumeIrradianceAt(sky, c, open_sky, ns, e);
    } else {
      SkyIrradiance(sky, ns[0], ns[1], ns[2], e);
    }
  }
  return Float3{e[0], e[1], e[2]};
}

/// whether the 4 pixels of a 2x2 quad (row-major) share one sky-volume blend: all hit a surface
/// (q.Hit(c)) of one geom (q.Geom(c)) with bitwise equal geometric normals (q.Ng(c, ng)), their
/// points (q.P(c, p), m) within 1 mm of the first's tangent plane and within a quarter probe
/// `spacing` of the first point on every axis (the volume interpolates probes one spacing apart,
/// so across such a quad it changes far less than 8-bit output resolves). *mean: the quad's mean
/// point, 0.25 p summed in pixel order (valid where true).
template <class Quad>
PB_HOST_DEVICE inline bool SkyQuadSharesBlend(const Quad& q, float spacing, float mean[3]) {
  float ng0[3], p0[3];
  for (int c = 0; c < 4; ++c) {
    if (!q.Hit(c)) return false;
    if (c == 0) {
      q.Ng(0, ng0);
      q.P(0, p0);
      continue;
    }
    float ng[3];
    q.Ng(c, ng);
    if (q.Geom(c) != q.Geom(0) || !(ng[0] == ng0[0] && ng[1] == ng0[1] && ng[2] == ng0[2]))
      return false;
  }
  const float max_extent = 0.25f * spacing;
  constexpr float kPlaneTolM = 1e-3f;
  mean[0] = mean[1] = mean[2] = 0;
  for (int c = 0; c < 4; ++c) {
    float p[3];
    q.P(c, p);
    const float dp[3] = {p[0] - p0[0], p[1] - p0[1], p[2] - p0[2]};
    // x + (y + z): the order of Eigen's 3-vector dot, which the CPU used before.
    const float n_dp = ng0[0] * dp[0] + (ng0[1] * dp[1] + ng0[2] * dp[2]);
    if (!(fabsf(n_dp) <= kPlaneTolM && fabsf(dp[0]) <= max_extent && fabsf(dp[1]) <= max_extent &&
          fabsf(dp[2]) <= max_extent))
      return false;
    mean[0] += 0.25f * p[0];
    mean[1] += 0.25f * p[1];
    mean[2] += 0.25f * p[2];
  }
  return true;
}

/// a quad of the frame's PixelGeometry records (SkyQuadSharesBlend's Quad): pixel c at
/// geometry[quad[c]].
struct GeometryQuad {
  const PixelGeometry* geometry;
  const int64_t* quad;
  PB_HOST_DEVICE bool Hit(int c) const { return geometry[quad[c]].hit != 0; }
  PB_HOST_DEVICE int Geom(int c) const { return geometry[quad[c]].geom; }
  PB_HOST_DEVICE void Ng(int c, float ng[3]) const {
    const Float3& n = geometry[quad[c]].ng;
    ng[0] = n.x, ng[1] = n.y, ng[2] = n.z;
  }
  PB_HOST_DEVICE void P(int c, float p[3]) const {
    const Float3& q = geometry[quad[c]].p_or_d;
    p[0] = q.x, p[1] = q.y, p[2] = q.z;
  }
};

/// the sky terms (RealtimeFrameView::sky_term) of the 2x2 quad at even (u0, v0) of a
/// width-pixel image (pixels at or below row1 and right of the image left out), as
/// RealtimeIntegrator's TileSkyIrradiance: with a sky volume, a quad whose pixels see one flat
/// face (one geom, bitwise equal geometric normals, points on one plane within 1 mm and within
/// a quarter probe spacing of each other) shares one blend at the quad's mean point; other
/// pixels take PixelSkyTerm.
PB_HOST_DEVICE inline void QuadSkyTerms(const SkyModelPod& sky, const SkyVolumePod& volume,
                                        const PixelGeometry* geometry, int width, int row1, int u0,
                                        int v0, Float3* out) {
  const int64_t i00 = static_cast<int64_t>(v0) * width + u0;
  const int64_t quad[4] = {i00, i00 + 1, i00 + width, i00 + width + 1};
  const bool occluded = !volume.empty();
  float mean[3];
  if (occluded && u0 + 1 < width && v0 + 1 < row1 &&
      SkyQuadSharesBlend(GeometryQuad{geometry, quad}, volume.spacing, mean)) {
    const PixelGeometry& g0 = geometry[quad[0]];
    const float n0[3] = {g0.ng.x, g0.ng.y, g0.ng.z};
    float c[kSkyShStride];
    bool open_sky;
    SkyVolumeBlend(volume, mean, n0, c, &open_sky);
    for (int k = 0; k < 4; ++k) {
      const PixelGeometry& g = geometry[quad[k]];
      const float ns[3] = {g.ns.x, g.ns.y, g.ns.z};
      float e[3];
      SkyVolumeIrradianceAt(sky, c, open_sky, ns, e);
      out[quad[k]] = Float3{e[0], e[1], e[2]};
    }
    return;
  }
  for (int c = 0; c < 4; ++c)
    if (u0 + (c & 1) < width && v0 + (c >> 1) < row1)
      out[quad[c]] = PixelSkyTerm(sky, volume, geometry[quad[c]]);
}

/// the sky term of a mirrored ray (RealtimeFrameView::mirror_sky) from its geometry g
/// (TraceMirrorRay): where it hits, the occluded sky irradiance at the hit's shading normal
/// (SkyVolumeIrradiance, no shared blends: render/cpu/mirror_layer.cc's MirrorRadiance), where
/// it escapes SkyBackground; false (out unchanged) where the pixel traced none (hit -1).
PB_HOST_DEVICE inline bool MirrorSkyTerm(const SkyModelPod& sky, const SkyVolumePod& volume,
                                         const PixelGeometry& g, Float3* out) {
  if (g.hit < 0) return false;
  float e[3];
  if (g.hit == 0) {
    SkyBackground(sky, g.p_or_d.x, g.p_or_d.y, g.p_or_d.z, e);
  } else {
    const float p[3] = {g.p_or_d.x, g.p_or_d.y, g.p_or_d.z}, ns[3] = {g.ns.x, g.ns.y, g.ns.z};
    SkyVolumeIrradiance(volume, sky, p, ns, e);
  }
  *out = Float3{e[0], e[1], e[2]};
  return true;
}

/// the geometry of pixel (u, v)'s primary ray for the sky terms; *t_hit: its hit's t
/// (0 on a miss); *hit_out (if given): the closest hit; *surface_out (if given, where the ray
/// hits): the shading point's material terms (ShadeRealtimeStored).
PB_HOST_DEVICE inline PixelGeometry PrimaryGeometry(const RealtimeFrameView& f, int u, int v,
                                                    float* t_hit, TraceHit* hit_out = nullptr,
                                                    SurfaceTerms* surface_out = nullptr) {
  const TraceRay r = PrimaryRay(f.camera, u, v);
  TraceHit h;
  TraceClosest(f.scene, r, &h);
  if (hit_out) *hit_out = h;
  PixelGeometry g;
  *t_hit = 0;
  const float d_len = sqrtf(r.d.x * r.d.x + r.d.y * r.d.y + r.d.z * r.d.z);
  if (h.instance < 0) {
    const float inv = 1.0f / d_len;
    g.p_or_d = Float3{r.d.x * inv, r.d.y * inv, r.d.z * inv};
    return g;
  }
  *t_hit = h.t;
  const ShadingPoint sp = EvaluateSurface(f, r, h, d_len);
  g.hit = 1;
  g.geom = f.scene.records[f.scene.prims[h.prim].record].geom;
  g.p_or_d = sp.p;
  g.ng = sp.ng;
  g.ns = sp.n;
  g.mirror = sp.mirror;
  if (surface_out) {
    surface_out->base = sp.base;
    surface_out->emission = sp.emission;
    surface_out->roughness = sp.roughness;
    surface_out->metallic = sp.metallic;
    surface_out->specular = sp.specular;
    surface_out->occlusion = sp.occlusion;
  }
  return g;
}

/// light j's contribution c at surface point p (shadow ray direction wi, distance dist:
/// LightContribution's) attenuated by the frame's homogeneous media on the way to the light, as
/// RealtimeIntegrator's surface loop: c as it is where it is 0, else c times
/// MediaLightTransmittance (the world light volume's channel-mean value where p lies in it and
/// it holds light j, else the closed form). the CPU looks every light up at once per point
/// (LightTransmittances): the same values; here one light at a time, so that nothing stays live
/// across the light loop.
PB_HOST_DEVICE inline Float3 MediaAttenuated(const RealtimeFrameView& f, int j, const Float3& p,
                                             const Float3& wi, float dist, const Float3& c) {
  if (c.x == 0 && c.y == 0 && c.z == 0) return c;
  const float pp[3] = {p.x, p.y, p.z}, ww[3] = {wi.x, wi.y, wi.z};
  const Float3 T = MediaLightTransmittance(f.media, j, pp, ww, dist);
  return Float3{c.x * T.x, c.y * T.y, c.z * T.z};
}

/// lights whose unshadowed contribution ShadeRealtimePoint keeps between its two loops (the
/// others are evaluated twice).
constexpr int kShadeCachedLights = 16;

/// where ShadeRealtimePoint keeps lights 0 .. capacity() - 1's unshadowed terms (contribution c,
/// unit direction wi towards the light, distance dist, LightContribution's) between its two
/// loops: the thread's own arrays (on the device, local memory: the shading kernel's stack).
struct LocalLightTerms {
  Float3 c[kShadeCachedLights], wi[kShadeCachedLights];
  float dist[kShadeCachedLights];
  /// the lights kept: kShadeCachedLights
  PB_HOST_DEVICE int capacity() const { return kShadeCachedLights; }
  /// keeps light j's terms (j < capacity())
  PB_HOST_DEVICE void Put(int j, const Float3& cj, const Float3& wij, float dj) {
    c[j] = cj, wi[j] = wij, dist[j] = dj;
  }
  /// light j's terms as Put kept them
  PB_HOST_DEVICE void Get(int j, Float3* cj, Float3* wij, float* dj) const {
    *cj = c[j], *wij = wi[j], *dj = dist[j];
  }
};

/// LocalLightTerms in memory the caller owns, interleaved over `stride` threads (the shading
/// kernel's shared memory): float k (0 .. 6: c, wi,
/// dist) of light j at at[(kLightTermFloats j + k) stride], `at` the block's array plus the
/// thread's index, so a warp's lanes touch consecutive words. the same values as
/// LocalLightTerms, so the same bits.
struct StridedLightTerms {
  /// floats a light's terms take
  static constexpr int kLightTermFloats = 7;
  float* at = nullptr;  ///< the thread's first float
  int stride = 0;       ///< the threads sharing the array (floats between two of a thread's)
  int lights = 0;       ///< the lights kept (at most kShadeCachedLights)
  /// the lights kept
  PB_HOST_DEVICE int capacity() const { return lights; }
  /// keeps light j's terms (j < capacity())
  PB_HOST_DEVICE void Put(int j, const Float3& cj, const Float3& wij, float dj) {
    float* q = at + kLightTermFloats * j * stride;
    q[0] = cj.x, q[stride] = cj.y, q[2 * stride] = cj.z;
    q[3 * stride] = wij.x, q[4 * stride] = wij.y, q[5 * stride] = wij.z;
    q[6 * stride] = dj;
  }
  /// light j's terms as Put kept them
  PB_HOST_DEVICE void Get(int j, Float3* cj, Float3* wij, float* dj) const {
    const float* q = at + kLightTermFloats * j * stride;
    *cj = Float3{q[0], q[stride], q[2 * stride]};
    *wij = Float3{q[3 * stride], q[4 * stride], q[5 * stride]};
    *dj = q[6 * stride];
  }
};

/// what ShadeRealtimePoint computes at a shading point before its lights: the BRDF's
/// coefficients (BrdfCoefficientsOf: c_diff, f0, a2 = alpha^2), n . wo, the ambient radiance
/// Le + E_sky / pi (c_diff (1 - S) + S) and the shadow rays' origin (OffsetOrigin off the
/// geometric normal).
struct ShadeSetup {
  Float3 c_diff, f0;
  float a2 = 0, n_v = 0;
  Float3 L;
  F3 origin;
};

/// the radiance of a shading point before its lights, for a float or Lanes: its emission plus
/// the ambient term E_sky / pi (c_diff (1 - S) + S), sky_E the occluded sky irradiance on the
/// shading normal times the material's occlusion, S the split-sum fit (EnvBrdfApprox at
/// max(n_v, 0) and the roughness) of the BRDF's c_diff and f0 (BrdfCoefficientsOf).
template <typename T, typename V>
PB_HOST_DEVICE inline V AmbientRadiance(const V& emission, const V& sky_E, const V& c_diff,
                                        const V& f0, const T& n_v, const T& roughness) {
  const V spec = EnvBrdfApprox<T, V>(f0, pbm::Max(n_v, 0.0f), roughness);
  const V reflect{c_diff.x * (1.0f - spec.x) + spec.x, c_diff.y * (1.0f - spec.y) + spec.y,
                  c_diff.z * (1.0f - spec.z) + spec.z};
  return V{emission.x + (sky_E.x * pbm::kInvPi) * reflect.x,
           emission.y + (sky_E.y * pbm::kInvPi) * reflect.y,
           emission.z + (sky_E.z * pbm::kInvPi) * reflect.z};
}

/// whether a lit light of luminance lum (> 0) at a point whose unshadowed total is `total` is
/// worth a shadow ray: it is not negligible (kGpuNegligibleLight of the total); a float or
/// every lane.
template <typename T, typename M>
PB_HOST_DEVICE inline M ShadowRayWorthTracing(const T& lum, const T& total) {
  return pbm::GreaterEqual(lum, T(kGpuNegligibleLight * total));
}

/// ShadeSetup of shading point sp with sky term `sky` (E_sky where the pixel's ray hits).
PB_HOST_DEVICE inline ShadeSetup BeginShadePoint(const ShadingPoint& sp, const Float3& sky) {
  ShadeSetup s;
  const float roughness = sp.roughness;
  const Float3 emission = sp.emission;
  const float occlusion = sp.occlusion;
  // the BRDF's coefficients and the ambient term E_sky / pi (c_diff (1 - S) + S); the shading
  // normal where it faces the viewer, else the geometric one (UsableShadingNormal).
  float alpha;
  BrdfCoefficientsOf<float, Float3>(sp.base, roughness, sp.metallic, sp.specular, &s.c_diff, &s.f0,
                                    &alpha);
  s.a2 = alpha * alpha;
  s.n_v = pbm::Dot<float>(sp.n, sp.wo);
  s.L = AmbientRadiance<float, Float3>(emission, occlusion * sky, s.c_diff, s.f0, s.n_v, roughness);
  // shadow rays start off the surface on the lit side.
  s.origin = OffsetOrigin(sp.p, sp.ng);
  return s;
}

/// light j's unshadowed contribution at shading point sp of pixel (u, v) (LightContribution,
/// attenuated by the frame's media where kMedia and f.has_media), its shadow ray's unit
/// direction *wi and distance *dist.
template <bool kMedia>
PB_HOST_DEVICE inline Float3 UnshadowedLight(const RealtimeFrameView& f, int j, int u, int v,
                                             const ShadingPoint& sp, const ShadeSetup& s,
                                             Float3* wi, float* dist) {
  Float3 c = LightContribution(f, j, u, v, sp.p, sp.n, sp.ng, sp.wo, s.n_v, s.c_diff, s.f0, s.a2,
                               wi, dist);
  if (kMedia && f.has_media != 0) c = MediaAttenuated(f, j, sp.p, *wi, *dist, c);
  return c;
}

/// ShadeRealtimePoint's first light loop: every light's unshadowed term (the first
/// terms.capacity() kept in `terms`), returns the unshadowed total's luminance (the ambient
/// term's and every light's), which decides the shadow rays worth tracing.
template <bool kMedia, class Terms>
PB_HOST_DEVICE inline float UnshadowedLights(const RealtimeFrameView& f, int u, int v,
                                             const ShadingPoint& sp, const ShadeSetup& s,
                                             Terms& terms) {
  float total = pbm::Luminance709(s.L.x, s.L.y, s.L.z);
  const int cached = terms.capacity();
  for (int j = 0; j < f.num_lights; ++j) {
    Float3 wi;
    float dist;
    const Float3 c = UnshadowedLight<kMedia>(f, j, u, v, sp, s, &wi, &dist);
    if (j < cached) terms.Put(j, c, wi, dist);
    total += pbm::Luminance709(c.x, c.y, c.z);
  }
  return total;
}

/// light j's unshadowed terms for ShadeRealtimePoint's second loop: kept in `terms`, or
/// evaluated again (UnshadowedLight) for lights from terms.capacity() on.
template <bool kMedia, class Terms>
PB_HOST_DEVICE inline Float3 KeptLight(const RealtimeFrameView& f, int j, int u, int v,
                                       const ShadingPoint& sp, const ShadeSetup& s,
                                       const Terms& terms, Float3* wi, float* dist) {
  if (j < terms.capacity()) {
    Float3 c;
    terms.Get(j, &c, wi, dist);
    return c;
  }
  return UnshadowedLight<kMedia>(f, j, u, v, sp, s, wi, dist);
}

/// a light of luminance lum (> 0) at a pixel whose unshadowed total is `total` gets a shadow
/// ray: it casts shadows and is not negligible (ShadowRayWorthTracing).
PB_HOST_DEVICE inline bool WantsShadowRay(const LightPod& l, float lum, float total) {
  return l.cast_shadow != 0 && ShadowRayWorthTracing<float, bool>(lum, total);
}

/// the shadow ray from `origin` towards a light in unit direction wi at distance dist (stops
/// just short of it; +inf stays +inf).
PB_HOST_DEVICE inline TraceRay ShadowRayOf(const F3& origin, const Float3& wi, float dist) {
  TraceRay sr;
  sr.o = origin;
  sr.d = ToF3(wi);
  sr.tmin = 0;
  sr.tmax = dist * (1.0f - 1e-4f);  // +inf stays +inf
  return sr;
}

/// ShadeRealtimePoint's second loop at light j (lit: luminance > 0) of pixel `pixel` of
/// n_pixels, once its shadow ray's verdict is known (traced false: none traced, the light is
/// added as it is): a light with an extent leaves its contribution c and the verdict to the
/// shared visibility (f.area_c, f.area_vis); another adds c to *L unless occluded.
PB_HOST_DEVICE inline void AddLitLight(const RealtimeFrameView& f, int j, int64_t pixel,
                                       int64_t n_pixels, const Float3& c, bool traced,
                                       bool occluded, Float3* L) {
  if (traced) {
    if (IsExtendedLightPod(f.lights[j])) {
      f.area_vis[j * n_pixels + pixel] = occluded ? 0 : 1;
      f.area_c[j * n_pixels + pixel] = c;
      return;
    }
    if (occluded) return;
  }
  *L = *L + c;
}

/// the part ShadeRealtimePoint and ShadeQueuedLights share, at the shading point sp of pixel
/// (u, v) with sky term `sky`: sets *ambient to the ambient term (the sum's start) and
/// f.total[pixel] to the lights' unshadowed total (UnshadowedLights into `terms`), then calls
/// lit(j, pixel, n_pixels, c, traced, origin, wi, dist) for each light j in light order whose
/// unshadowed contribution c (KeptLight) has a luminance > 0; traced: whether its shadow ray,
/// ShadowRayOf(origin, wi, dist), is worth tracing (WantsShadowRay).
template <bool kMedia, class Terms, class Lit>
PB_HOST_DEVICE inline void ForEachLitLight(const RealtimeFrameView& f, int u, int v,
                                           const ShadingPoint& sp, const Float3& sky, Terms& terms,
                                           Float3* ambient, Lit&& lit) {
  const int64_t pixel = static_cast<int64_t>(v) * f.camera.width + u;
  const int64_t n_pixels = static_cast<int64_t>(f.camera.width) * f.camera.height;
  const ShadeSetup s = BeginShadePoint(sp, sky);
  *ambient = s.L;
  // one sample per light; the unshadowed total decides which shadow rays are worth tracing.
  const float total = UnshadowedLights<kMedia>(f, u, v, sp, s, terms);
  f.total[pixel] = total;
  for (int j = 0; j < f.num_lights; ++j) {
    Float3 wi;
    float dist;
    const Float3 c = KeptLight<kMedia>(f, j, u, v, sp, s, terms, &wi, &dist);
    const float lum = pbm::Luminance709(c.x, c.y, c.z);
    if (!(lum > 0)) continue;
    lit(j, pixel, n_pixels, c, WantsShadowRay(f.lights[j], lum, total), s.origin, wi, dist);
  }
}

/// the radiance of pixel (u, v) (ShadeRealtimePixel) from the shading point sp of its primary hit
/// and its sky term (f.sky_term), after f.area_vis is cleared for the pixel: the ambient term, the
/// lights and their shadow rays, each light attenuated by the frame's media where f.has_media.
/// kMedia false: for frames known to have none (f.has_media must be 0): the media's code is left
/// out, so the kernels of frames without media keep their registers. terms: where the lights'
/// unshadowed terms wait between the two loops (LocalLightTerms, StridedLightTerms); lights from
/// terms.capacity() on are evaluated twice. ShadeQueuedLights and SumQueuedLights do the same
/// with the shadow rays traced apart (the same bits).
template <bool kMedia = true, class Terms>
PB_HOST_DEVICE inline Float3 ShadeRealtimePoint(const RealtimeFrameView& f, int u, int v,
                                                const ShadingPoint& sp, const Float3& sky,
                                                Terms& terms) {
  // lights in order: negligible or shadowless contributions are added as they are, the others
  // after a shadow ray; those of lights with an extent wait for their neighbours' verdicts.
  Float3 L;
  ForEachLitLight<kMedia>(f, u, v, sp, sky, terms, &L,
                          [&](int j, int64_t pixel, int64_t n_pixels, const Float3& c, bool traced,
                              const F3& origin, const Float3& wi, float dist) {
                            const bool occluded =
                                traced && TraceOccluded(f.scene, ShadowRayOf(origin, wi, dist));
                            AddLitLight(f, j, pixel, n_pixels, c, traced, occluded, &L);
                          });
  return L;
}

/// the most lights a frame may have for its shadow rays to go through a queue
/// (the shading kernels' queued shadow rays: a pixel's lights are bits of 32-bit masks).
constexpr int kMaxQueuedShadowLights = 32;

/// what ShadeQueuedLights leaves of a pixel for SumQueuedLights: the lights whose unshadowed
/// contribution is lit (luminance > 0; kept in f.area_c) and, of those, the ones whose shadow
/// ray went to the queue (bit j: light j).
struct QueuedLightMasks {
  uint32_t lit = 0;
  uint32_t traced = 0;
};

/// a shadow ray in the queue: its origin, unit direction and tmax (ShadowRayOf; tmin 0), and
/// key = pixel kMaxQueuedShadowLights + light (pixel: in the whole batch, camera-major).
struct alignas(16) QueuedShadowRay {
  F3 o, d;
  float tmax = 0;
  uint32_t key = 0;
};

/// the queue entry of shadow ray r (tmin 0) of light j at pixel `pixel` (in the whole batch).
PB_HOST_DEVICE inline QueuedShadowRay QueueEntryOf(const TraceRay& r, uint32_t pixel, int j) {
  QueuedShadowRay e;
  e.o = r.o;
  e.d = r.d;
  e.tmax = r.tmax;
  e.key = pixel * kMaxQueuedShadowLights + static_cast<uint32_t>(j);
  return e;
}

/// the shadow ray of queue entry r (tmin 0).
PB_HOST_DEVICE inline TraceRay QueuedRay(const QueuedShadowRay& r) {
  TraceRay sr;
  sr.o = r.o;
  sr.d = r.d;
  sr.tmin = 0;
  sr.tmax = r.tmax;
  return sr;
}

/// ShadeRealtimePoint up to its shadow rays (f.num_lights <= kMaxQueuedShadowLights), pass 1
/// of 3 of the queued shadow rays (ShadeQueuedKernel, TraceQueuedKernel, SumQueuedKernel): the
/// unshadowed terms and total as there, every lit light's contribution kept in f.area_c at [j n +
/// pixel], each shadow ray that ShadeRealtimePoint traces handed to queue.Push(j, ray) instead, in
/// light order; returns the ambient term (the sum's start) and sets *masks. pass 2 traces the
/// queue (TraceOccluded, any order: each verdict is the ray's own), pass 3 sums the lights
/// (SumQueuedLights).
template <bool kMedia, class Terms, class Queue>
PB_HOST_DEVICE inline Float3 ShadeQueuedLights(const RealtimeFrameView& f, int u, int v,
                                               const ShadingPoint& sp, const Float3& sky,
                                               Terms& terms, Queue& queue,
                                               QueuedLightMasks* masks) {
  QueuedLightMasks m;
  Float3 L;
  ForEachLitLight<kMedia>(f, u, v, sp, sky, terms, &L,
                          [&](int j, int64_t pixel, int64_t n_pixels, const Float3& c, bool traced,
                              const F3& origin, const Float3& wi, float dist) {
                            m.lit |= 1u << j;
                            f.area_c[j * n_pixels + pixel] = c;
                            if (!traced) return;
                            m.traced |= 1u << j;
                            queue.Push(j, ShadowRayOf(origin, wi, dist));
                          });
  *masks = m;
  return L;
}

/// pass 3 of the queued shadow rays: pixel `pixel` (of n_pixels)'s radiance from the ambient
/// term L (ShadeQueuedLights' return), its masks and the verdicts of its queued rays (bit j of
/// `occluded`: light j's ray hit something): its lit lights added in light order as
/// ShadeRealtimePoint's second loop adds them (AddLitLight: the same operations in the same
/// order, so the same bits).
PB_HOST_DEVICE inline Float3 SumQueuedLights(const RealtimeFrameView& f, int64_t pixel,
                                             int64_t n_pixels, Float3 L, const QueuedLightMasks& m,
                                             uint32_t occluded) {
  for (uint32_t b = m.lit; b != 0; b &= b - 1) {
    const int j = LowestSetBit(b);
    AddLitLight(f, j, pixel, n_pixels, f.area_c[j * n_pixels + pixel], (m.traced >> j & 1u) != 0,
                (occluded >> j & 1u) != 0, &L);
  }
  return L;
}

/// ShadeRealtimePoint with the lights' terms in the thread's own arrays (LocalLightTerms).
template <bool kMedia = true>
PB_HOST_DEVICE inline Float3 ShadeRealtimePoint(const RealtimeFrameView& f, int u, int v,
                                                const ShadingPoint& sp, const Float3& sky) {
  LocalLightTerms terms;
  return ShadeRealtimePoint<kMedia>(f, u, v, sp, sky, terms);
}

/// starts the shading of pixel (u, v): no light's shared visibility is known yet (its area_vis
/// entries set to -1), and returns the pixel's sky term.
PB_HOST_DEVICE inline Float3 BeginRealtimePixel(const RealtimeFrameView& f, int u, int v) {
  const int64_t pixel = static_cast<int64_t>(v) * f.camera.width + u;
  const int64_t n_pixels = static_cast<int64_t>(f.camera.width) * f.camera.height;
  for (int j = 0; j < f.num_lights; ++j) f.area_vis[j * n_pixels + pixel] = -1;
  return f.sky_term[pixel];
}

/// the shading point of pixel (u, v) from what the geometry pass kept of it: its primary
/// geometry g (a hit) and material terms t (PrimaryGeometry's surface_out; the view direction
/// from PrimaryRay as EvaluateSurface): EvaluateSurface's shading point, without evaluating the
/// surface (textures, normal map) a second time.
PB_HOST_DEVICE inline ShadingPoint StoredShadingPoint(const RealtimeFrameView& f, int u, int v,
                                                      const PixelGeometry& g,
                                                      const SurfaceTerms& t) {
  const TraceRay r = PrimaryRay(f.camera, u, v);
  const float d_len = sqrtf(r.d.x * r.d.x + r.d.y * r.d.y + r.d.z * r.d.z);
  ShadingPoint sp;
  sp.wo = -Float3{r.d.x / d_len, r.d.y / d_len, r.d.z / d_len};
  sp.p = g.p_or_d;
  sp.ng = g.ng;
  sp.n = g.ns;
  sp.base = t.base;
  sp.emission = t.emission;
  sp.roughness = t.roughness;
  sp.metallic = t.metallic;
  sp.specular = t.specular;
  sp.occlusion = t.occlusion;
  sp.mirror = g.mirror;
  return sp;
}

/// ShadeRealtimePixel of pixel (u, v) from what the geometry pass kept of its shading point
/// (StoredShadingPoint of g and t): the same shading point, so the same radiance. kMedia and
/// terms: ShadeRealtimePoint's.
template <bool kMedia = true, class Terms>
PB_HOST_DEVICE inline Float3 ShadeRealtimeStored(const RealtimeFrameView& f, int u, int v,
                                                 const PixelGeometry& g, const SurfaceTerms& t,
                                                 Terms& terms) {
  const Float3 sky = BeginRealtimePixel(f, u, v);
  if (g.hit == 0) return sky;
  return ShadeRealtimePoint<kMedia>(f, u, v, StoredShadingPoint(f, u, v, g, t), sky, terms);
}

/// ShadeRealtimeStored up to its shadow rays (pass 1 of the queued shadow rays,
/// ShadeQueuedLights): the pixel's area_vis cleared, returns its sky term where its ray
/// escapes (no lights: *masks empty), else ShadeQueuedLights' ambient term.
template <bool kMedia, class Terms, class Queue>
PB_HOST_DEVICE inline Float3 ShadeQueuedStored(const RealtimeFrameView& f, int u, int v,
                                               const PixelGeometry& g, const SurfaceTerms& t,
                                               Terms& terms, Queue& queue,
                                               QueuedLightMasks* masks) {
  const Float3 sky = BeginRealtimePixel(f, u, v);
  *masks = QueuedLightMasks();
  if (g.hit == 0) return sky;
  return ShadeQueuedLights<kMedia>(f, u, v, StoredShadingPoint(f, u, v, g, t), sky, terms, queue,
                                   masks);
}

/// ShadeRealtimeStored with the lights' terms in the thread's own arrays (LocalLightTerms).
template <bool kMedia = true>
PB_HOST_DEVICE inline Float3 ShadeRealtimeStored(const RealtimeFrameView& f, int u, int v,
                                                 const PixelGeometry& g, const SurfaceTerms& t) {
  LocalLightTerms terms;
  return ShadeRealtimeStored<kMedia>(f, u, v, g, t, terms);
}

/// the linear radiance of pixel (u, v) (the file comment's L; the sky term where the ray
/// escapes) without the shadowed light of lights with an extent: their unshadowed contribution
/// and the pixel's own shadow ray's verdict go to f.area_c and f.area_vis, resolved by
/// SharedVisibilityRays, SharedVisibilityFraction and SharedVisibilityResolve once every pixel
/// has them (as the CPU's RealtimeIntegrator defers them to ResolveSharedVisibility). every
/// light's unshadowed contribution is evaluated once (kShadeCachedLights of them).
PB_HOST_DEVICE inline Float3 ShadeRealtimePixel(const RealtimeFrameView& f, int u, int v) {
  const TraceRay r = PrimaryRay(f.camera, u, v);
  TraceHit h;
  TraceClosest(f.scene, r, &h);
  const Float3 sky = BeginRealtimePixel(f, u, v);
  if (h.instance < 0) return sky;
  const float d_len = sqrtf(r.d.x * r.d.x + r.d.y * r.d.y + r.d.z * r.d.z);
  return ShadeRealtimePoint(f, u, v, EvaluateSurface(f, r, h, d_len), sky);
}

}  // namespace penumbra::cuda
