#include "penumbra/render/cpu/path_integrator.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "penumbra/render/light/bsdf.h"
#include "penumbra/render/light/path_math.h"

namespace penumbra {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
// shadow rays towards a point at distance d stop this fraction short of it.
constexpr float kShadowShorten = 1e-4f;

Float3 F3(const Eigen::Vector3f& v) { return Float3{v.x(), v.y(), v.z()}; }
Eigen::Vector3f E3(const Float3& v) { return Eigen::Vector3f(v.x, v.y, v.z); }

// a point or spot light with a radius that casts shadows: a sphere that rays can hit (the
// shared terms of render/light/path_math.h).
struct Lamp {
  int light = -1;  // index into LightSampler::lights()
  const LightPod* pod = nullptr;

  // radiance (cd/m^2) the sphere sends towards world point p: I s / (pi r^2).
  Eigen::Vector3f RadianceTowards(const Eigen::Vector3f& p) const {
    return E3(LampRadianceTowards(*pod, F3(p)));
  }
  // solid angle of the sphere seen from p (outside), 0 from inside.
  float SolidAngle(const Eigen::Vector3f& p) const { return LampSolidAngle(*pod, F3(p)); }
  // nearest t in (tmin, tmax) where o + t d (d unit) meets the sphere from outside.
  bool Intersect(const Eigen::Vector3f& o, const Eigen::Vector3f& d, float tmin, float tmax,
                 float* t) const {
    return LampIntersect(*pod, F3(o), F3(d), tmin, tmax, t);
  }
};

// a directional light with an angular radius that casts shadows: a disc in the sky.
struct SunDisc {
  int light = -1;
  Eigen::Vector3f to_sun{0, 0, 1};
  float cos_max = 1;
  float solid_angle = 0;
  Eigen::Vector3f L{0, 0, 0};  // E / Omega, cd/m^2
};

// the frame's lights as this integrator sees them.
struct FrameLights {
  std::vector<Lamp> lamps;
  std::vector<SunDisc> suns;
  std::vector<int> lamp_of_light, sun_of_light;  // per light: index or -1
  bool sky_active = false;

  explicit FrameLights(const FrameContext& ctx) {
    const std::vector<LightPod>& pl = ctx.lights->pods();
    lamp_of_light.assign(pl.size(), -1);
    sun_of_light.assign(pl.size(), -1);
    for (size_t i = 0; i < pl.size(); ++i) {
      const LightPod& l = pl[i];
      SunDiscPod disc;
      if (SunDiscOf(l, &disc)) {
        SunDisc s;
        s.light = static_cast<int>(i);
        s.to_sun = E3(disc.to_sun);
        s.cos_max = disc.cos_max;
        s.solid_angle = disc.solid_angle;
        s.L = E3(disc.L);
        sun_of_light[i] = static_cast<int>(suns.size());
        suns.push_back(s);
      } else if (IsLampSphere(l)) {
        Lamp lamp;
        lamp.light = static_cast<int>(i);
        lamp.pod = &l;
        lamp_of_light[i] = static_cast<int>(lamps.size());
        lamps.push_back(lamp);
      }
    }
    const Eigen::Vector3f up = ctx.sky->Irradiance({0, 0, 1});
    const Eigen::Vector3f down = ctx.sky->Irradiance({0, 0, -1});
    sky_active = up.maxCoeff() > 0 || down.maxCoeff() > 0;
  }

  // the nearest lamp hit by o + t d (d unit) for t in (tmin, tmax), or -1.
  int NearestLamp(const Eigen::Vector3f& o, const Eigen::Vector3f& d, float tmin, float tmax,
                  float* t_out, int skip = -1) const {
    int best = -1;
    float best_t = tmax;
    for (size_t k = 0; k < lamps.size(); ++k) {
      if (static_cast<int>(k) == skip) continue;
      float t;
      if (lamps[k].Intersect(o, d, tmin, best_t, &t)) best = static_cast<int>(k), best_t = t;
    }
    *t_out = best_t;
    return best;
  }
  bool LampBlocks(const Eigen::Vector3f& o, const Eigen::Vector3f& d, float tmax,
                  int skip = -1) const {
    float t;
    return !lamps.empty() && NearestLamp(o, d, 0.0f, tmax, &t, skip) >= 0;
  }
};

}  // namespace

PathIntegrator::PathIntegrator(const SceneDescription& scene) : emitters_(scene) {}

int64_t PathIntegrator::RenderTile(const FrameContext& ctx, const PrimaryHits& primary,
                                   const FrameBuffers& out) const {
  const FrameLights fl(ctx);
  const RayScene& scene = *ctx.scene;
  const std::vector<Pose>& X_WB = scene.X_WB();
  const int spp = std::max(1, ctx.settings->samples_per_pixel);
  const int max_bounces = std::max(1, ctx.settings->max_bounces);
  const int num_lights = ctx.lights->size();
  const PixelTile& tile = primary.tile;
  const MediaFrame* fx = ctx.effects;
  const MediaScene* media = fx != nullptr ? fx->media() : nullptr;
  const ParticleScene* particles = fx != nullptr ? fx->particles() : nullptr;
  const float wetness = fx != nullptr ? fx->surface_wetness() : 0.0f;
  const float spread = ctx.camera->pixel_spread_rad();
  int64_t rays = 0;

  for (int i = 0; i < tile.width * tile.height; ++i) {
    const int u = tile.x0 + i % tile.width, v = tile.y0 + i / tile.width;
    double sum[3] = {0, 0, 0};
    double albedo_sum[3] = {0, 0, 0};
    int albedo_count = 0;

    for (int s = 0; s < spp; ++s) {
      // a stop request ends the tile between samples (the frame is then discarded)
      if (ctx.stop_request != nullptr && ctx.stop_request->load(std::memory_order_relaxed) != 0) {
        if (ctx.stopped != nullptr) ctx.stopped->store(true, std::memory_order_relaxed);
        return rays;
      }
      Rng rng(ctx.PixelStream(u, v, s));
      const float jx = rng.Uniform(), jy = rng.Uniform();
      const Ray cam = ctx.camera->GenerateRay(static_cast<float>(u) + jx - 0.5f,
                                              static_cast<float>(v) + jy - 0.5f);
      Ray ray;
      ray.o = cam.o;
      ray.d = cam.d.normalized();

      Eigen::Vector3f L(0, 0, 0), beta(1, 1, 1);
      float prev_pdf = 0;  // BSDF or phase density of the direction that led here
      Eigen::Vector3f prev_p(0, 0, 0);
      bool from_camera = true;
      // length of the path from the camera to the current ray's origin, m: the pixel's ray
      // cone is spread * that length wide there (texture level of detail, see header).
      float path_m = 0;

      // transmittance of the media along a shadow ray o + t d (d unit), t in [0, dist].
      auto media_T = [&](const Eigen::Vector3f& o, const Eigen::Vector3f& d, float dist) {
        return media->Transmittance(o, d, 0.0f, dist, &rng);
      };

      // next-event estimation at a surface or medium vertex at p: `eval(wi, &f, &pdf)` gives
      // the BSDF / phase value (times |cos| at surfaces) and its sampling density, `spawn(wi)`
      // the shadow ray in direction wi, `spawn_to(q)` the one towards point q.
      auto next_event = [&](const Eigen::Vector3f& p, auto&& eval, auto&& spawn, auto&& spawn_to) {
        // every analytic light.
        for (int j = 0; j < num_lights; ++j) {
          const float u1 = rng.Uniform(), u2 = rng.Uniform();
          LightSample ls;
          if (!ctx.lights->Sample(j, p, u1, u2, &ls)) continue;
          Eigen::Vector3f f;
          float f_pdf;
          eval(ls.wi, &f, &f_pdf);
          if (!(f.maxCoeff() > 0)) continue;
          Eigen::Vector3f c;
          const int sun = fl.sun_of_light[j], lamp_j = fl.lamp_of_light[j];
          if (sun >= 0) {
            // uniform in the disc's cone: f E = f L Omega, weighted against BSDF sampling.
            c = f.cwiseProduct(ls.E) * PowerHeuristic(1.0f / fl.suns[sun].solid_angle, f_pdf);
          } else if (lamp_j >= 0) {
            const Lamp& lp = fl.lamps[lamp_j];
            const float omega = lp.SolidAngle(p);
            if (!(omega > 0)) continue;
            c = f.cwiseProduct(lp.RadianceTowards(p)) *
                (omega * PowerHeuristic(1.0f / omega, f_pdf));
          } else {
            c = f.cwiseProduct(ls.E);
          }
          if (!(c.maxCoeff() > 0)) continue;
          if (ls.cast_shadow) {
            Ray sr = spawn(ls.wi);
            sr.tmax = std::isinf(ls.distance) ? kInf : ls.distance * (1.0f - kShadowShorten);
            ++rays;
            if (scene.Occluded(sr) || fl.LampBlocks(sr.o, sr.d, sr.tmax, lamp_j)) continue;
            if (media != nullptr) c = c.cwiseProduct(media_T(sr.o, sr.d, sr.tmax));
          } else if (media != nullptr) {
            c = c.cwiseProduct(media_T(p, ls.wi, ls.distance));
          }
          L += beta.cwiseProduct(c);
        }

        // the sky.
        if (fl.sky_active) {
          const float u1 = rng.Uniform(), u2 = rng.Uniform();
          float pdf = 0;
          const Eigen::Vector3f wi = ctx.sky->Sample(u1, u2, &pdf);
          if (pdf > 0) {
            Eigen::Vector3f f;
            float f_pdf;
            eval(wi, &f, &f_pdf);
            if (f.maxCoeff() > 0) {
              const Ray sr = spawn(wi);
              ++rays;
              if (!scene.Occluded(sr) && !fl.LampBlocks(sr.o, sr.d, kInf)) {
                const float w = PowerHeuristic(pdf, f_pdf);
                Eigen::Vector3f c =
                    (w / pdf) * beta.cwiseProduct(f.cwiseProduct(ctx.sky->Radiance(wi)));
                if (media != nullptr) c = c.cwiseProduct(media_T(sr.o, sr.d, kInf));
                L += c;
              }
            }
          }
        }

        // one emissive geom.
        if (!emitters_.empty()) {
          const float u0 = rng.Uniform(), u1 = rng.Uniform(), u2 = rng.Uniform();
          EmitterSample es;
          if (emitters_.Sample(X_WB, p, u0, u1, u2, &es)) {
            Eigen::Vector3f f;
            float f_pdf;
            eval(es.wi, &f, &f_pdf);
            if (f.maxCoeff() > 0) {
              const Ray sr = spawn_to(es.p_W);
              ++rays;
              const float dist = (es.p_W - sr.o).norm() * sr.tmax;
              if (!scene.Occluded(sr) && !fl.LampBlocks(sr.o, es.wi, dist)) {
                const float w = PowerHeuristic(es.pdf, f_pdf);
                Eigen::Vector3f c = (w / es.pdf) * beta.cwiseProduct(f.cwiseProduct(es.Le));
                if (media != nullptr) c = c.cwiseProduct(media_T(sr.o, es.wi, dist));
                L += c;
              }
            }
          }
        }
      };

      for (int vertex = 0;; ++vertex) {
        SurfaceHit hit;
        const bool found = scene.Intersect(ray, &hit);
        ++rays;
        const float t_surface = found ? hit.t : kInf;

        // a lamp sphere in front of the surface ends the path.
        float t_lamp;
        const int lamp =
            fl.lamps.empty() ? -1 : fl.NearestLamp(ray.o, ray.d, ray.tmin, t_surface, &t_lamp);

        if (fx != nullptr) {
          const float t_end = lamp >= 0 ? t_lamp : t_surface;
          // camera rays see particle streaks, each covering the pixel with probability alpha.
          ParticleHit ph;
          const bool particle = particles != nullptr && from_camera &&
                                particles->Intersect(ray, t_end, &ph) && rng.Uniform() < ph.alpha;
          const float t_stop = particle ? ph.t : t_end;
          if (media != nullptr) {
            float t_scatter;
            MediumPoint mp;
            const TrackEvent ev =
                media->Track(ray.o, ray.d, ray.tmin, t_stop, &rng, &beta, &L, &t_scatter, &mp);
            if (ev == TrackEvent::kAbsorb) break;
            if (ev == TrackEvent::kScatter) {
              if (vertex >= max_bounces) break;
              const Eigen::Vector3f p = ray.o + t_scatter * ray.d;
              const Eigen::Vector3f wo = -ray.d;
              next_event(
                  p,
                  [&](const Eigen::Vector3f& wi, Eigen::Vector3f* f, float* pdf) {
                    *pdf = mp.Phase(wo.dot(wi));
                    *f = Eigen::Vector3f::Constant(*pdf);
                  },
                  [&](const Eigen::Vector3f& wi) {
                    Ray r;
                    r.o = p;
                    r.d = wi;
                    return r;
                  },
                  [&](const Eigen::Vector3f& q) {
                    Ray r;
                    r.o = p;
                    r.d = q - p;
                    r.tmax = 1.0f - 1e-4f;
                    return r;
                  });
              if (vertex >= kRussianRouletteStartVertex) {
                const float q = std::min(1.0f, beta.maxCoeff());
                if (!(rng.Uniform() < q)) break;
                beta /= q;
              }
              const float u0 = rng.Uniform(), u1 = rng.Uniform(), u2 = rng.Uniform();
              float pdf;
              const Eigen::Vector3f wi = mp.SamplePhase(wo, u0, u1, u2, &pdf);
              if (!(pdf > 0) || !(beta.maxCoeff() > 0) || !beta.allFinite()) break;
              // phase sampling is exact: f / pdf = 1.
              prev_pdf = pdf;
              prev_p = p;
              from_camera = false;
              path_m += t_scatter * ray.d.norm();
              ray.o = p;
              ray.d = wi;
              ray.tmin = 0.0f;
              ray.tmax = kInf;
              continue;
            }
          }
          if (particle) {
            const Eigen::Vector3f p = ray.o + ph.t * ray.d;
            L += beta.cwiseProduct(particles->Shade(ph, p, *ctx.lights, fx->sky_ambient()));
            break;
          }
        }

        if (lamp >= 0) {
          const Lamp& lp = fl.lamps[lamp];
          float w = 1.0f;
          if (!from_camera) {
            const float omega = lp.SolidAngle(prev_p);
            w = PowerHeuristic(prev_pdf, omega > 0 ? 1.0f / omega : 0.0f);
          }
          L += w * beta.cwiseProduct(lp.RadianceTowards(ray.o));
          break;
        }

        if (!found) {
          // the ray leaves the scene: sky and sun discs.
          if (fl.sky_active) {
            const float w = from_camera ? 1.0f : PowerHeuristic(prev_pdf, ctx.sky->Pdf(ray.d));
            // the camera and mirrors see the MJCF skybox where there is one (Background).
            const bool seen = from_camera || prev_pdf == kInf;
            L +=
                w * beta.cwiseProduct(seen ? ctx.sky->Background(ray.d) : ctx.sky->Radiance(ray.d));
          }
          for (const SunDisc& sun : fl.suns) {
            if (ray.d.dot(sun.to_sun) < sun.cos_max) continue;
            const float w = from_camera ? 1.0f : PowerHeuristic(prev_pdf, 1.0f / sun.solid_angle);
            L += w * beta.cwiseProduct(sun.L);
          }
          break;
        }

        const float d_len = ray.d.norm();
        const float hit_path_m = path_m + hit.t * d_len;
        const TextureFootprint footprint = ConeFootprint(spread, hit_path_m, ray.d / d_len, hit);
        SurfaceMaterial mat = ctx.materials->EvaluateAndMapNormal(&hit, footprint);
        if (wetness > 0) ApplySurfaceWetness(wetness, hit.ns_W, &mat.pbr);
        if (vertex == 0) {
          for (int k = 0; k < 3; ++k) albedo_sum[k] += mat.pbr.base_color[k];
          ++albedo_count;
        }
        if (mat.emission.maxCoeff() > 0) {
          float w = 1.0f;
          if (!from_camera)
            w = PowerHeuristic(prev_pdf, emitters_.Pdf(X_WB, hit.geom, prev_p, hit.p_W, hit.ng_W));
          L += w * beta.cwiseProduct(mat.emission);
        }
        if (vertex >= max_bounces) break;

        // the mirror layer (weight r = mat.mirror), picked with probability r: the path goes on
        // along the mirrored ray with its throughput unchanged (r L_mirror / r), or goes on
        // through the BRDF below ((1 - r) L_brdf / (1 - r)). a delta direction: the next
        // vertex's emitters count with weight 1 (prev_pdf = inf). no draw without a mirror, so
        // other materials keep their random numbers.
        if (mat.mirror > 0 && rng.Uniform() < mat.mirror) {
          const Eigen::Vector3f d = ray.d / d_len;
          const Eigen::Vector3f n = hit.ng_W;  // faces the ray
          const Eigen::Vector3f wi = d - 2.0f * d.dot(n) * n;
          prev_pdf = kInf;
          prev_p = hit.p_W;
          from_camera = false;
          path_m = hit_path_m;
          ray = SpawnRay(hit, wi);
          continue;
        }

        const Eigen::Vector3f wo = -ray.d;
        const Bsdf bsdf(mat.pbr, hit.ns_W, hit.ng_W, wo);
        next_event(
            hit.p_W,
            [&](const Eigen::Vector3f& wi, Eigen::Vector3f* f, float* pdf) {
              *f = bsdf.Eval(wi);
              *pdf = f->maxCoeff() > 0 ? bsdf.Pdf(wi) : 0.0f;
            },
            [&](const Eigen::Vector3f& wi) { return SpawnRay(hit, wi); },
            [&](const Eigen::Vector3f& q) { return SpawnRayTo(hit, q); });

        // Russian roulette, then continue along a BSDF sample.
        if (vertex >= kRussianRouletteStartVertex) {
          const float q = std::min(1.0f, beta.maxCoeff());
          if (!(rng.Uniform() < q)) break;
          beta /= q;
        }
        const float ul = rng.Uniform(), u1 = rng.Uniform(), u2 = rng.Uniform();
        BsdfSample bs;
        if (!bsdf.Sample(ul, u1, u2, &bs)) break;
        beta = beta.cwiseProduct(bs.f_cos) / bs.pdf;
        if (!(beta.maxCoeff() > 0) || !beta.allFinite()) break;
        prev_pdf = bs.pdf;
        prev_p = hit.p_W;
        from_camera = false;
        path_m = hit_path_m;
        ray = SpawnRay(hit, bs.wi);
      }

      if (!L.allFinite()) continue;  // dropped (see header)
      for (int k = 0; k < 3; ++k) sum[k] += L[k];
    }

    float* px = out.radiance->at(u, v);
    for (int k = 0; k < 3; ++k) px[k] = static_cast<float>(sum[k] / spp);
    if (out.albedo) {
      float* a = out.albedo->at(u, v);
      for (int k = 0; k < 3; ++k)
        a[k] = albedo_count > 0 ? static_cast<float>(albedo_sum[k] / albedo_count) : 0.0f;
    }
    if (out.normal) {
      float* nn = out.normal->at(u, v);
      if (primary.did_hit[i]) {
        const SurfaceHit& h = primary.hits[i];
        const Eigen::Vector3f wo = -primary.rays[i].d.normalized();
        const Eigen::Vector3f n = h.ns_W.dot(wo) > 0 ? h.ns_W : h.ng_W;
        nn[0] = n.x(), nn[1] = n.y(), nn[2] = n.z();
      } else {
        nn[0] = nn[1] = nn[2] = 0.0f;
      }
    }
  }
  return rays;
}

}  // namespace penumbra
