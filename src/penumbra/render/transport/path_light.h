#pragma once
// the pathtraced tier's light at a path vertex: the frame's view (PathFrameView), the emissive
// geoms' sampling (PathEmitters, EmitterSampler's), the lamp spheres along a ray, the surface and
// medium vertices and next-event estimation (PathNextEvent: one sample of every light, the sky
// and one emissive geom, MIS-weighted, with the media's transmittance), as the chain of
// path_trace.h draws them.

#include <cstdint>

#include "penumbra/core/host_device.h"
#include "penumbra/core/rng.h"
#include "penumbra/render/bvh/bvh_traversal.h"
#include "penumbra/render/light/bsdf_math.h"
#include "penumbra/render/light/emitter_math.h"
#include "penumbra/render/light/light_math.h"
#include "penumbra/render/light/path_math.h"
#include "penumbra/render/media/media_scene_math.h"
#include "penumbra/render/shading_math.h"
#include "penumbra/render/sky/sky_eval_math.h"
#include "penumbra/render/sky/sky_sampling_math.h"
#include "penumbra/render/transport/path_streaks.h"
#include "penumbra/render/transport/scene_view.h"
#include "penumbra/render/transport/surface.h"

namespace penumbra::cuda {

/// Russian roulette starts at this path vertex (0 = the first hit: after 3 bounces); a path goes
/// on with probability q = min(1, its throughput's largest channel), reweighted by 1 / q.
constexpr int kPathRussianRouletteStartVertex = 3;
/// shadow rays towards a point at distance d stop this fraction short of it.
constexpr float kPathShadowShorten = 1e-4f;

/// the scene's emissive geoms as the path samples them (EmitterSampler's,
/// render/light/emitter_math.h): num emitters in pick order, their plain data, emitted radiance
/// (cd/m^2) and pick cdf (num + 1 values), per SceneDescription geom (num_geoms) its emitter or -1,
/// and per emitter its geom's world pose for the frame, 12 doubles (rotation row-major,
/// translation). num 0: none.
struct PathEmitters {
  int32_t num = 0;
  const EmitterPod* pods = nullptr;
  const Float3* Le = nullptr;
  const double* pick_cdf = nullptr;
  const int32_t* emitter_of_geom = nullptr;
  int32_t num_geoms = 0;
  const double* poses = nullptr;
};

/// EmitterSampler::Pdf: the solid-angle density with which the emitter sampling at p returns
/// the direction to point p_hit (unit normal n_hit) on geom `geom`; 0 for geoms it never samples.
PB_HOST_DEVICE inline float PathEmitterPdf(const PathEmitters& em, int geom, const Float3& p,
                                           const Float3& p_hit, const Float3& n_hit) {
  if (geom < 0 || geom >= em.num_geoms) return 0.0f;
  const int k = em.emitter_of_geom[geom];
  if (k < 0) return 0.0f;
  const double p_pick = em.pick_cdf[k + 1] - em.pick_cdf[k];
  if (!(p_pick > 0)) return 0.0f;
  const double pd[3] = {p.x, p.y, p.z}, hd[3] = {p_hit.x, p_hit.y, p_hit.z},
               nd[3] = {n_hit.x, n_hit.y, n_hit.z};
  return EmitterPointPdf(em.pods[k], p_pick, em.poses + 12 * k + 9, pd, hd, nd);
}

/// everything a pathtraced frame reads and writes, as device (or host) pointers.
struct PathFrameView {
  /// the scene, camera (with its ray tables for lens distortion or motion), materials, textures,
  /// posed geoms and lights, the sky (pod) and the frame key: RealtimeFrameData::View's.
  RealtimeFrameView rt;
  SkySamplingPod sky_sampling;  ///< the frame sky's sampling tables (SkyModel::sampling_pod)
  int32_t sky_active = 0;       ///< the sky sends light (its irradiance up or down is > 0)
  int32_t spp = 1;              ///< samples per pixel (>= 1)
  int32_t max_bounces = 1;      ///< >= 1
  PathEmitters emitters;        ///< the emissive geoms (none: num 0)
  /// the frame's participating media (MediaScene::View's or its device copy; none: empty, and
  /// the paths run TracePath<false>)
  MediaSceneView media;
  /// the frame's particle streaks (path_streaks.h: PathStreakBuild::View or its device copy;
  /// none: num 0, and the paths run TracePath<kMedia, false>)
  PathStreaks streaks;
  /// per pixel (row-major, width x height): the mean radiance, the mean base colour of the
  /// first surface over the samples that hit one (the denoiser's albedo), and the pixel-centre
  /// hit's usable shading normal (0 where it escapes) and z-depth (0 where it escapes).
  Float3* radiance = nullptr;
  Float3* albedo = nullptr;
  Float3* normal = nullptr;
  float* depth = nullptr;
};

/// the lamp sphere nearest along o + t d (d unit) for t in (tmin, tmax), skipping light `skip`:
/// its light index (or -1) and *t_out its t (tmax where none).
PB_HOST_DEVICE inline int PathNearestLamp(const RealtimeFrameView& f, const Float3& o,
                                          const Float3& d, float tmin, float tmax, float* t_out,
                                          int skip = -1) {
  int best = -1;
  float best_t = tmax;
  for (int j = 0; j < f.num_lights; ++j) {
    if (j == skip || !IsLampSphere(f.lights[j])) continue;
    float t;
    if (LampIntersect(f.lights[j], o, d, tmin, best_t, &t)) best = j, best_t = t;
  }
  *t_out = best_t;
  return best;
}

/// the origin of a ray leaving surface point p (unit geometric normal ng facing the arriving
/// ray) in direction d: pushed off the surface on d's side (render/ray.h's SpawnRay).
PB_HOST_DEVICE inline TraceRay PathSpawnRay(const Float3& p, const Float3& ng, const Float3& d) {
  const float side = EigenDot(d, ng) >= 0 ? 1.0f : -1.0f;
  TraceRay r;
  r.o = OffsetOrigin(p, Float3{side * ng.x, side * ng.y, side * ng.z});
  r.d = ToF3(d);
  r.tmin = 0;
  r.tmax = INFINITY;
  return r;
}

/// max(c.x, c.y, c.z) as Eigen's maxCoeff.
PB_HOST_DEVICE inline float PathMax3(const Float3& c) { return pbm::Max(pbm::Max(c.x, c.y), c.z); }
PB_HOST_DEVICE inline Float3 PathMul(const Float3& a, const Float3& b) {
  return Float3{a.x * b.x, a.y * b.y, a.z * b.z};
}

/// a surface vertex of a path as PathNextEvent reads it: the BSDF's value times |cos| and its
/// density (Eval), the shadow ray in a direction off the surface (Spawn, render/ray.h's SpawnRay)
/// and towards a point (SpawnTo, SpawnRayTo: d = q - origin, stopping kPathShadowShorten short).
struct PathSurfaceVertex {
  const ShadingPoint* sp;
  const BsdfPod* b;
  PB_HOST_DEVICE Float3 Point() const { return sp->p; }
  PB_HOST_DEVICE void Eval(const Float3& wi, Float3* f, float* pdf) const {
    *f = BsdfEval(*b, wi);
    *pdf = PathMax3(*f) > 0 ? BsdfPdf(*b, wi) : 0.0f;
  }
  PB_HOST_DEVICE TraceRay Spawn(const Float3& wi) const { return PathSpawnRay(sp->p, sp->ng, wi); }
  PB_HOST_DEVICE TraceRay SpawnTo(const Float3& q) const {
    const Float3& p = sp->p;
    TraceRay sr = PathSpawnRay(p, sp->ng, Float3{q.x - p.x, q.y - p.y, q.z - p.z});
    const Float3 o = ToFloat3(sr.o);
    sr.d = ToF3(Float3{q.x - o.x, q.y - o.y, q.z - o.z});
    sr.tmax = 1.0f - kPathShadowShorten;
    return sr;
  }
};

/// a medium vertex (a real scattering event at p, wo back along the arriving ray, the media's
/// point mp): the phase function as value and density (the CPU's lambda), rays from p itself.
struct PathMediumVertex {
  Float3 p, wo;
  const MediumPointPod* mp;
  PB_HOST_DEVICE Float3 Point() const { return p; }
  PB_HOST_DEVICE void Eval(const Float3& wi, Float3* f, float* pdf) const {
    *pdf = MediaPhase(*mp, EigenDot(wo, wi));
    *f = Float3{*pdf, *pdf, *pdf};
  }
  PB_HOST_DEVICE TraceRay Spawn(const Float3& wi) const {
    TraceRay r;
    r.o = ToF3(p);
    r.d = ToF3(wi);
    r.tmin = 0;
    r.tmax = INFINITY;
    return r;
  }
  PB_HOST_DEVICE TraceRay SpawnTo(const Float3& q) const {
    TraceRay r = Spawn(Float3{q.x - p.x, q.y - p.y, q.z - p.z});
    r.tmax = 1.0f - 1e-4f;
    return r;
  }
};

/// the media's transmittance along o + t d, t in [0, dist] (MediaTransmittanceOf), or 1 where
/// the frame has no media (kMedia false: no call).
template <bool kMedia>
PB_HOST_DEVICE inline Float3 PathMediaT(const PathFrameView& pf, const Float3& o, const Float3& d,
                                        float dist, Rng* rng) {
  if (!kMedia) return Float3{1, 1, 1};
  const float o3[3] = {o.x, o.y, o.z}, d3[3] = {d.x, d.y, d.z};
  return MediaTransmittanceOf(pf.media, o3, d3, 0.0f, dist, rng);
}

/// next-event estimation at vertex `vx` (PathSurfaceVertex or PathMediumVertex) with path
/// throughput beta, its shadow rays traced by `tracer` (path_trace.h's Tracer), drawing from rng as
/// the CPU's next_event: one sample of every light, then the sky, then one emissive geom; with
/// kMedia every unoccluded shadow ray's contribution times the media's transmittance. adds to *L.
template <bool kMedia, typename Vertex, class Tracer>
PB_HOST_DEVICE inline void PathNextEvent(const PathFrameView& pf, const Tracer& tracer,
                                         const Vertex& vx, const Float3& beta, Rng* rng,
                                         Float3* L) {
  const RealtimeFrameView& f = pf.rt;
  const Float3 p = vx.Point();
  for (int j = 0; j < f.num_lights; ++j) {
    const float u1 = rng->Uniform(), u2 = rng->Uniform();
    const LightPod& l = f.lights[j];
    Float3 wi, E;
    float dist;
    bool valid;
    SampleLight<float, Float3, bool, true>(l, p, u1, u2, &wi, &dist, &E, &valid);
    if (!valid) continue;
    Float3 fv;
    float f_pdf;
    vx.Eval(wi, &fv, &f_pdf);
    if (!(PathMax3(fv) > 0)) continue;
    Float3 c;
    SunDiscPod sun;
    const bool lamp = IsLampSphere(l);
    if (SunDiscOf(l, &sun)) {
      // uniform in the disc's cone: f E = f L Omega, weighted against BSDF sampling.
      c = PathMul(fv, E) * PowerHeuristic(1.0f / sun.solid_angle, f_pdf);
    } else if (lamp) {
      const float omega = LampSolidAngle(l, p);
      if (!(omega > 0)) continue;
      c = PathMul(fv, LampRadianceTowards(l, p)) * (omega * PowerHeuristic(1.0f / omega, f_pdf));
    } else {
      c = PathMul(fv, E);
    }
    if (!(PathMax3(c) > 0)) continue;
    if (l.cast_shadow != 0) {
      TraceRay sr = vx.Spawn(wi);
      sr.tmax = dist == INFINITY ? INFINITY : dist * (1.0f - kPathShadowShorten);
      if (tracer.Occluded(sr)) continue;
      float t;
      if (PathNearestLamp(f, ToFloat3(sr.o), wi, 0.0f, sr.tmax, &t, lamp ? j : -1) >= 0) continue;
      if (kMedia) c = PathMul(c, PathMediaT<kMedia>(pf, ToFloat3(sr.o), wi, sr.tmax, rng));
    } else if (kMedia) {
      c = PathMul(c, PathMediaT<kMedia>(pf, p, wi, dist, rng));
    }
    *L = *L + PathMul(beta, c);
  }
  if (pf.sky_active != 0) {
    const float u1 = rng->Uniform(), u2 = rng->Uniform();
    float pdf = 0, d[3];
    SkySampleDirection(pf.sky_sampling, u1, u2, &pdf, d);
    if (pdf > 0) {
      const Float3 wi{d[0], d[1], d[2]};
      Float3 fv;
      float f_pdf;
      vx.Eval(wi, &fv, &f_pdf);
      if (PathMax3(fv) > 0) {
        const TraceRay sr = vx.Spawn(wi);
        float t;
        if (!tracer.Occluded(sr) &&
            PathNearestLamp(f, ToFloat3(sr.o), wi, 0.0f, INFINITY, &t) < 0) {
          const float w = PowerHeuristic(pdf, f_pdf);
          float sky[3];
          SkyRadiance(f.sky, wi.x, wi.y, wi.z, sky);
          Float3 c = PathMul(beta, PathMul(fv, Float3{sky[0], sky[1], sky[2]})) * (w / pdf);
          if (kMedia) c = PathMul(c, PathMediaT<kMedia>(pf, ToFloat3(sr.o), wi, INFINITY, rng));
          *L = *L + c;
        }
      }
    }
  }
  // one emissive geom (EmitterSampler::Sample), its shadow ray towards the sampled point.
  const PathEmitters& em = pf.emitters;
  if (em.num > 0) {
    const float u0 = rng->Uniform(), u1 = rng->Uniform(), u2 = rng->Uniform();
    double u_rest = 0;
    const int k = EmitterPickFromCdf(em.pick_cdf, em.num, u0, &u_rest);
    const double p_pick = em.pick_cdf[k + 1] - em.pick_cdf[k];
    const double pd[3] = {p.x, p.y, p.z};
    EmitterPoint ep;
    if (p_pick > 0 && EmitterSamplePoint(em.pods[k], p_pick, em.poses + 12 * k,
                                         em.poses + 12 * k + 9, pd, u_rest, u1, u2, &ep)) {
      const Float3 q{static_cast<float>(ep.q[0]), static_cast<float>(ep.q[1]),
                     static_cast<float>(ep.q[2])};
      const Float3 wi{static_cast<float>(ep.wi[0]), static_cast<float>(ep.wi[1]),
                      static_cast<float>(ep.wi[2])};
      Float3 fv;
      float f_pdf;
      vx.Eval(wi, &fv, &f_pdf);
      if (PathMax3(fv) > 0) {
        const TraceRay sr = vx.SpawnTo(q);
        const Float3 o = ToFloat3(sr.o), dq = ToFloat3(sr.d);
        const float dist = sqrtf(EigenDot(dq, dq)) * sr.tmax;
        float t;
        if (!tracer.Occluded(sr) && PathNearestLamp(f, o, wi, 0.0f, dist, &t) < 0) {
          const float w = PowerHeuristic(ep.pdf, f_pdf);
          Float3 c = PathMul(beta, PathMul(fv, em.Le[k])) * (w / ep.pdf);
          if (kMedia) c = PathMul(c, PathMediaT<kMedia>(pf, o, wi, dist, rng));
          *L = *L + c;
        }
      }
    }
  }
}

}  // namespace penumbra::cuda
