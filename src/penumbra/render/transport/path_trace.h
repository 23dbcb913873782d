#pragma once
// the pathtraced tier, per pixel, as PB_HOST_DEVICE functions over plain data, written once for
// both processors: path_kernels.cu runs them on the GPU (one thread a run of one pixel's samples,
// the runs of a pixel then summed in run order: PathSampleRange, PathFinishPixel) and the CPU
// backend (render/cpu/path_tiles.h) runs PathTracePixel over Embree, pixel by pixel in tiles.
//
// the model: unidirectional path tracing with next-event estimation and multiple importance
// sampling (Veach, "Robust Monte Carlo methods for light transport simulation", PhD thesis,
// Stanford 1997, ch. 9; power heuristic with beta = 2); lamp spheres and sun discs are visible to
// every ray (not in the realtime tier); with max_bounces = b a path gathers light that scattered
// at most b times (b = 1: direct lighting). outputs per pixel: the mean radiance (non-finite
// paths dropped); the denoiser guides: albedo = mean base colour of the first surface over the
// samples that hit one, normal = shading normal of the pixel-centre hit, depth = its t.
// textures are filtered over the pixel's ray cone (spread angle Camera::pixel_spread_rad, width
// at a vertex that angle times the path's length from the camera: the cone of a chain of flat
// mirrors; rough bounces' spread is left out). the draws, with media and particles:
//
//   per sample s of pixel (u, v): Rng(PixelStream(u, v, s)) (core/rng.h, the same draws in the
//   same order), a camera ray jittered over the pixel (two draws); at each vertex the lamp
//   spheres in front of the surface (a hit ends the path), the sky and the sun discs where the
//   ray escapes (MIS-weighted against the previous vertex's BSDF density; the camera and mirrors
//   see the MJCF skybox), the surface's emission, the mirror layer (one draw, where it applies),
//   next-event estimation (one sample of every light: two draws each, MIS for lamp spheres and
//   sun discs; the sky: two draws, MIS; one emissive geom: three draws, MIS), Russian roulette from
//   kPathRussianRouletteStartVertex (one draw) and the BSDF's sample (three draws);
//   with media (TracePath<true>): before each surface the free flight's spectral delta tracking
//   (MediaTrackOf; its draws), at a real scattering event next-event estimation through the
//   phase function, Russian roulette and the phase function's sample (three draws), and on every
//   shadow ray the media's transmittance (MediaTransmittanceOf; draws inside grid boxes);
//   with particles (TracePath<..., true>): a camera ray that meets a streak (path_streaks.h)
//   in front of the lamp or surface stops there with probability alpha (one draw, before the
//   free flight, which then ends at the streak), adding the streak's radiance (ShadeStreak);
//
// the ray tracer is the chain's one seam to the processor: a Tracer (template parameter, passed
// by the caller) with Closest(const TraceRay&, TraceHit*) (hit->instance -1: none) and
// Occluded(const TraceRay&) -> bool, its hits numbered as pf.rt.scene's arrays (instance, prim,
// u, v, part, t), from which the surface at a hit is read (EvaluateSurface). the GPU passes
// BvhTracer (render/bvh/bvh_traversal.h) over pf.rt.scene, the CPU EmbreeTracer
// (render/cpu/embree_tracer.h: Embree's hits named as the BVH scene names them).
//
// with the shared formulas of render/: the BSDF (bsdf_math.h), the light samples (light_math.h,
// with LightSampler::Sample's normalisation), the lamp and sun terms and the power heuristic
// (path_math.h), the emissive geoms' sampling (emitter_math.h), the sky's radiance and
// background (sky_eval_math.h) and sampling
// (sky_sampling_math.h), the media (media_scene_math.h: MediaScene's tracking, transmittance and
// phase functions), dot products summed as the CPU's Eigen code sums them (EigenDot),
// and the materials with their textures over the path's ray cone as the
// realtime tier evaluates them (EvaluateSurface, surface.h). the GPU contracts
// multiply-adds and traces with its own BVH, so its paths differ from the CPU's by float
// rounding, which a path's branches (Russian roulette, lobe choice) can turn into other paths:
// the estimates agree in the mean (docs/journal/2026-11-29-path-cpu.md).

#include <cstdint>

#include "penumbra/core/host_device.h"
#include "penumbra/core/rng.h"
#include "penumbra/render/bvh/bvh_traversal.h"
#include "penumbra/render/light/bsdf_math.h"
#include "penumbra/render/light/path_math.h"
#include "penumbra/render/transport/path_light.h"
#include "penumbra/render/transport/path_streaks.h"
#include "penumbra/render/transport/scene_view.h"
#include "penumbra/render/transport/surface.h"

namespace penumbra::cuda {

/// a + t (b - a): exactly a where a == b (a camera's equal rows stay equal).
PB_HOST_DEVICE inline float PathLerp(float a, float b, float t) { return a + t * (b - a); }

/// the camera ray of sample (jx, jy) (each in [0, 1)) of pixel (u, v), as Camera::GenerateRay
/// casts it at (u + jx - 0.5, v + jy - 0.5), its direction not normalised: a pinhole in closed
/// form; a camera with ray tables (lens distortion, a moving camera; camera_rays.h, whose
/// entries are the pixel centres') with the undistorted coordinates and the row's pose
/// interpolated linearly between the pixel centres around the sample, extrapolated over the
/// image's outer half pixel. the interpolation differs from Camera::GenerateRay's exact
/// undistortion and PoseAtRow by the second order of the map over a pixel: at most 0.002 of a
/// pixel at 640x480 (0.02 at 64x48) for k1 -0.28 and a rolling shutter over a turning camera
/// (tests/render/cuda/path_host_test.cc, JitteredCameraRay).
PB_HOST_DEVICE inline TraceRay JitteredCameraRay(const PinholeCamera& c, int u, int v, float jx,
                                                 float jy) {
  const float fu = static_cast<float>(u) + jx - 0.5f, fv = static_cast<float>(v) + jy - 0.5f;
  float x = (fu - c.cx) * c.inv_fx, y = (fv - c.cy) * c.inv_fy;
  if (!c.xy && !c.rows) return NormalizedPixelRay(c.o, c.ex, c.ey, c.ez, x, y, 0.0f);
  // the two pixel centres around the sample on each axis (the outer two at an edge)
  const int u0 = c.width < 2 ? 0 : pbm::Clamp(jx < 0.5f ? u - 1 : u, 0, c.width - 2);
  const int v0 = c.height < 2 ? 0 : pbm::Clamp(jy < 0.5f ? v - 1 : v, 0, c.height - 2);
  const int u1 = c.width < 2 ? 0 : u0 + 1, v1 = c.height < 2 ? 0 : v0 + 1;
  const float tx = fu - static_cast<float>(u0), ty = fv - static_cast<float>(v0);
  if (c.xy) {
    const float* p00 = c.xy + 2 * (static_cast<int64_t>(v0) * c.width + u0);
    const float* p10 = c.xy + 2 * (static_cast<int64_t>(v0) * c.width + u1);
    const float* p01 = c.xy + 2 * (static_cast<int64_t>(v1) * c.width + u0);
    const float* p11 = c.xy + 2 * (static_cast<int64_t>(v1) * c.width + u1);
    x = PathLerp(PathLerp(p00[0], p10[0], tx), PathLerp(p01[0], p11[0], tx), ty);
    y = PathLerp(PathLerp(p00[1], p10[1], tx), PathLerp(p01[1], p11[1], tx), ty);
  }
  if (!c.rows) return NormalizedPixelRay(c.o, c.ex, c.ey, c.ez, x, y, 0.0f);
  const float* r0 = c.rows + 12 * static_cast<int64_t>(v0);
  const float* r1 = c.rows + 12 * static_cast<int64_t>(v1);
  float r[12];
  for (int k = 0; k < 12; ++k) r[k] = PathLerp(r0[k], r1[k], ty);
  return NormalizedPixelRay(F3{r[0], r[1], r[2]}, F3{r[3], r[4], r[5]}, F3{r[6], r[7], r[8]},
                            F3{r[9], r[10], r[11]}, x, y, 0.0f);
}

/// one path of sample s of pixel (u, v): its radiance (non-finite values are the caller's to
/// drop) and, where its camera ray meets a surface, that surface's base colour (*albedo,
/// *hit_first true). kMedia: the frame has media (pf.media not empty); kParticles: it has
/// particle streaks (pf.streaks.num > 0).
template <bool kMedia, bool kParticles = false, class Tracer>
PB_HOST_DEVICE inline Float3 TracePath(const PathFrameView& pf, const Tracer& tracer, int u, int v,
                                       int s, Float3* albedo, bool* hit_first) {
  const RealtimeFrameView& f = pf.rt;
  const PinholeCamera& c = f.camera;
  const uint64_t pixel =
      static_cast<uint64_t>(v) * static_cast<uint64_t>(c.width) + static_cast<uint64_t>(u);
  Rng rng(HashKeys(HashKeys(f.frame_key, pixel), static_cast<uint64_t>(s)));
  const float jx = rng.Uniform(), jy = rng.Uniform();
  // Camera::GenerateRay at (u + jx - 0.5, v + jy - 0.5), normalised
  TraceRay ray = JitteredCameraRay(c, u, v, jx, jy);
  ray.d = ToF3(bsdf_detail::Normalized(ToFloat3(ray.d)));

  Float3 L{0, 0, 0}, beta{1, 1, 1};
  float prev_pdf = 0;
  Float3 prev_p{0, 0, 0};
  bool from_camera = true;
  float path_m = 0;
  *hit_first = false;
  for (int vertex = 0;; ++vertex) {
    TraceHit h;
    tracer.Closest(ray, &h);
    const bool found = h.instance >= 0;
    const float t_surface = found ? h.t : INFINITY;
    const Float3 o = ToFloat3(ray.o), d = ToFloat3(ray.d);

    // a lamp sphere in front of the surface ends the path.
    float t_lamp;
    const int lamp = PathNearestLamp(f, o, d, ray.tmin, t_surface, &t_lamp);

    // camera rays see the particle streaks, each covering the pixel with probability alpha
    // (one draw where a streak lies in front of the lamp or surface); the free flight then
    // stops at the streak.
    const float t_end = lamp >= 0 ? t_lamp : t_surface;
    float t_stop = t_end;
    int streak = -1;
    if (kParticles && from_camera) {
      float t_streak;
      int k;
      if (PathStreakHit(pf.streaks, o, d, ray.tmin, t_end, &t_streak, &k) &&
          rng.Uniform() < pf.streaks.streaks[k].alpha) {
        streak = k;
        t_stop = t_streak;
      }
    }
    if (kMedia) {
      // the free flight through the media up to the streak, lamp or surface: absorbed,
      // scattered (a medium vertex: next events through the phase function, then its sample),
      // or through.
      const float o3[3] = {o.x, o.y, o.z}, d3[3] = {d.x, d.y, d.z};
      float t_scatter;
      MediumPointPod mp;
      const TrackEvent ev =
          MediaTrackOf(pf.media, o3, d3, ray.tmin, t_stop, &rng, &beta, &L, &t_scatter, &mp);
      if (ev == TrackEvent::kAbsorb) break;
      if (ev == TrackEvent::kScatter) {
        if (vertex >= pf.max_bounces) break;
        const Float3 p{o.x + t_scatter * d.x, o.y + t_scatter * d.y, o.z + t_scatter * d.z};
        const Float3 wo{-d.x, -d.y, -d.z};
        PathNextEvent<kMedia>(pf, tracer, PathMediumVertex{p, wo, &mp}, beta, &rng, &L);
        if (vertex >= kPathRussianRouletteStartVertex) {
          const float q = pbm::Min(1.0f, PathMax3(beta));
          if (!(rng.Uniform() < q)) break;
          beta = Float3{beta.x / q, beta.y / q, beta.z / q};
        }
        const float u0 = rng.Uniform(), u1 = rng.Uniform(), u2 = rng.Uniform();
        float pdf;
        const Float3 wi = MediaSamplePhase(mp, wo, u0, u1, u2, &pdf);
        if (!(pdf > 0) || !(PathMax3(beta) > 0) || !pbm::IsFinite(beta.x) ||
            !pbm::IsFinite(beta.y) || !pbm::IsFinite(beta.z))
          break;
        // phase sampling is exact: f / pdf = 1.
        prev_pdf = pdf;
        prev_p = p;
        from_camera = false;
        path_m += t_scatter * sqrtf(EigenDot(d, d));
        ray.o = ToF3(p);
        ray.d = ToF3(wi);
        ray.tmin = 0;
        ray.tmax = INFINITY;
        continue;
      }
    }
    if (kParticles && streak >= 0) {
      // the streak's radiance ends the path
      const Float3 p{o.x + t_stop * d.x, o.y + t_stop * d.y, o.z + t_stop * d.z};
      L = L + PathMul(beta, PathStreakRadiance(pf.streaks, pf.streaks.streaks[streak], p, d,
                                               f.lights, f.num_lights, f.volume));
      break;
    }

    if (lamp >= 0) {
      float w = 1.0f;
      if (!from_camera) {
        const float omega = LampSolidAngle(f.lights[lamp], prev_p);
        w = PowerHeuristic(prev_pdf, omega > 0 ? 1.0f / omega : 0.0f);
      }
      L = L + PathMul(beta, LampRadianceTowards(f.lights[lamp], o)) * w;
      break;
    }

    if (!found) {
      // the ray leaves the scene: sky and sun discs.
      if (pf.sky_active != 0) {
        const float w =
            from_camera ? 1.0f
                        : PowerHeuristic(prev_pdf, SkyDirectionPdf(pf.sky_sampling, d.x, d.y, d.z));
        // the camera and mirrors see the MJCF skybox where there is one (Background).
        const bool seen = from_camera || prev_pdf == INFINITY;
        float sky[3];
        if (seen) {
          SkyBackground(f.sky, d.x, d.y, d.z, sky);
        } else {
          SkyRadiance(f.sky, d.x, d.y, d.z, sky);
        }
        L = L + PathMul(beta, Float3{sky[0], sky[1], sky[2]}) * w;
      }
      for (int j = 0; j < f.num_lights; ++j) {
        SunDiscPod sun;
        if (!SunDiscOf(f.lights[j], &sun)) continue;
        if (EigenDot(d, sun.to_sun) < sun.cos_max) continue;
        const float w = from_camera ? 1.0f : PowerHeuristic(prev_pdf, 1.0f / sun.solid_angle);
        L = L + PathMul(beta, sun.L) * w;
      }
      break;
    }

    const float d_len = sqrtf(EigenDot(d, d));
    const float hit_path_m = path_m + h.t * d_len;
    const ShadingPoint sp = EvaluateSurface(f, ray, h, d_len, path_m);
    if (vertex == 0) {
      *albedo = sp.base;
      *hit_first = true;
    }
    if (PathMax3(sp.emission) > 0) {
      // MIS-weighted against the emitter sampling of the previous vertex (0 for geoms it does
      // not sample: weight 1).
      const int geom = f.scene.records[f.scene.prims[h.prim].record].geom;
      const float w =
          from_camera
              ? 1.0f
              : PowerHeuristic(prev_pdf, PathEmitterPdf(pf.emitters, geom, prev_p, sp.p, sp.ng));
      L = L + PathMul(beta, sp.emission) * w;
    }
    if (vertex >= pf.max_bounces) break;

    // the mirror layer (weight r), picked with probability r: the path goes on along the
    // mirrored ray with its throughput unchanged; no draw without a mirror.
    if (sp.mirror > 0 && rng.Uniform() < sp.mirror) {
      const Float3 du{d.x / d_len, d.y / d_len, d.z / d_len};
      const Float3& n = sp.ng;  // faces the ray
      const float k = 2.0f * EigenDot(du, n);
      const Float3 wi{du.x - k * n.x, du.y - k * n.y, du.z - k * n.z};
      prev_pdf = INFINITY;
      prev_p = sp.p;
      from_camera = false;
      path_m = hit_path_m;
      ray = PathSpawnRay(sp.p, sp.ng, wi);
      continue;
    }

    Float3 c_diff, f0;
    float alpha;
    BrdfCoefficientsOf<float, Float3>(sp.base, sp.roughness, sp.metallic, sp.specular, &c_diff, &f0,
                                      &alpha);
    const BsdfPod b = MakeBsdf(c_diff, f0, alpha, sp.n, sp.ng, Float3{-d.x, -d.y, -d.z});
    PathNextEvent<kMedia>(pf, tracer, PathSurfaceVertex{&sp, &b}, beta, &rng, &L);

    // Russian roulette, then continue along a BSDF sample.
    if (vertex >= kPathRussianRouletteStartVertex) {
      const float q = pbm::Min(1.0f, PathMax3(beta));
      if (!(rng.Uniform() < q)) break;
      beta = Float3{beta.x / q, beta.y / q, beta.z / q};
    }
    const float ul = rng.Uniform(), u1 = rng.Uniform(), u2 = rng.Uniform();
    Float3 wi, f_cos;
    float pdf;
    if (!SampleBsdf(b, ul, u1, u2, &wi, &f_cos, &pdf)) break;
    beta = Float3{beta.x * f_cos.x / pdf, beta.y * f_cos.y / pdf, beta.z * f_cos.z / pdf};
    if (!(PathMax3(beta) > 0) || !pbm::IsFinite(beta.x) || !pbm::IsFinite(beta.y) ||
        !pbm::IsFinite(beta.z))
      break;
    prev_pdf = pdf;
    prev_p = sp.p;
    from_camera = false;
    path_m = hit_path_m;
    ray = PathSpawnRay(sp.p, sp.ng, wi);
  }
  return L;
}

/// the sums of a run of one pixel's samples: radiance (non-finite paths dropped) and the base
/// colour of the first surface over the samples whose camera ray met one, in double.
struct PathPartial {
  double L[3] = {0, 0, 0};
  double albedo[3] = {0, 0, 0};
  int32_t albedo_count = 0;
};

/// samples [s0, s1) of pixel (u, v) (TracePath<kMedia, kParticles>), summed in sample order.
template <bool kMedia, bool kParticles = false, class Tracer>
PB_HOST_DEVICE inline PathPartial PathSampleRange(const PathFrameView& pf, const Tracer& tracer,
                                                  int u, int v, int s0, int s1) {
  PathPartial p;
  for (int s = s0; s < s1; ++s) {
    Float3 albedo;
    bool hit = false;
    const Float3 L = TracePath<kMedia, kParticles>(pf, tracer, u, v, s, &albedo, &hit);
    if (hit) {
      p.albedo[0] += albedo.x, p.albedo[1] += albedo.y, p.albedo[2] += albedo.z;
      ++p.albedo_count;
    }
    if (!pbm::IsFinite(L.x) || !pbm::IsFinite(L.y) || !pbm::IsFinite(L.z)) continue;
    p.L[0] += L.x, p.L[1] += L.y, p.L[2] += L.z;
  }
  return p;
}

/// pixel (u, v)'s outputs from the sums of all its pf.spp samples: the mean radiance and
/// albedo, and the pixel-centre ray's depth and usable shading normal (the CPU's denoiser
/// guides: its depth image's ray, and its normal rule).
template <class Tracer>
PB_HOST_DEVICE inline void PathFinishPixel(const PathFrameView& pf, const Tracer& tracer, int u,
                                           int v, const PathPartial& p) {
  const int64_t i = static_cast<int64_t>(v) * pf.rt.camera.width + u;
  const double spp = static_cast<double>(pf.spp);
  pf.radiance[i] = Float3{static_cast<float>(p.L[0] / spp), static_cast<float>(p.L[1] / spp),
                          static_cast<float>(p.L[2] / spp)};
  pf.albedo[i] = p.albedo_count > 0 ? Float3{static_cast<float>(p.albedo[0] / p.albedo_count),
                                             static_cast<float>(p.albedo[1] / p.albedo_count),
                                             static_cast<float>(p.albedo[2] / p.albedo_count)}
                                    : Float3{};
  const TraceRay r = PrimaryRay(pf.rt.camera, u, v);
  TraceHit h;
  tracer.Closest(r, &h);
  if (h.instance < 0) {
    pf.depth[i] = 0;
    pf.normal[i] = Float3{};
    return;
  }
  const float d_len = sqrtf(r.d.x * r.d.x + r.d.y * r.d.y + r.d.z * r.d.z);
  const ShadingPoint sp = EvaluateSurface(pf.rt, r, h, d_len);
  pf.depth[i] = h.t;
  pf.normal[i] = sp.n;
}

/// samples [s0, s1) of pixel (u, v) by the TracePath instance of the frame: TracePath<true, ...>
/// where it has media (pf.media), TracePath<..., true> where it has particle streaks
/// (pf.streaks.num > 0); PathSampleRange's sums.
template <class Tracer>
PB_HOST_DEVICE inline PathPartial PathSamples(const PathFrameView& pf, const Tracer& tracer, int u,
                                              int v, int s0, int s1) {
  const bool media = MediaAny(pf.media), particles = pf.streaks.num > 0;
  return particles ? (media ? PathSampleRange<true, true>(pf, tracer, u, v, s0, s1)
                            : PathSampleRange<false, true>(pf, tracer, u, v, s0, s1))
                   : (media ? PathSampleRange<true>(pf, tracer, u, v, s0, s1)
                            : PathSampleRange<false>(pf, tracer, u, v, s0, s1));
}

/// pixel (u, v) of a pathtraced frame in one run: its pf.spp samples one after the other
/// (PathSamples), summed in sample order in double (the bits of one PathSampleRange over them
/// all), then PathFinishPixel. `stop()` is asked before every sample: once it returns true the
/// pixel is left unwritten and false is returned (a stop waits for at most one path).
template <class Tracer, class Stop>
PB_HOST_DEVICE inline bool PathTracePixel(const PathFrameView& pf, const Tracer& tracer, int u,
                                          int v, const Stop& stop) {
  PathPartial p;
  for (int s = 0; s < pf.spp; ++s) {
    if (stop()) return false;
    // one sample's sums are its values (0 + x is x): adding them in order is the one range's sum
    const PathPartial q = PathSamples(pf, tracer, u, v, s, s + 1);
    for (int c = 0; c < 3; ++c) p.L[c] += q.L[c], p.albedo[c] += q.albedo[c];
    p.albedo_count += q.albedo_count;
  }
  PathFinishPixel(pf, tracer, u, v, p);
  return true;
}

/// the sample runs of a frame of n pixels and spp samples on a processor that wants about
/// `threads` threads at once: runs = clamp(ceil(threads / n), 1, spp) runs a pixel of
/// ceil(spp / runs) samples each (the last may be shorter or, for run counts that do not divide
/// spp, empty).
PB_HOST_DEVICE inline int PathRunsPerPixel(int64_t n, int spp, int64_t threads) {
  const int64_t r = n > 0 ? (threads + n - 1) / n : 1;
  return static_cast<int>(r < 1 ? 1 : (r > spp ? spp : r));
}

}  // namespace penumbra::cuda
