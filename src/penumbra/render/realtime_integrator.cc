#include "penumbra/render/realtime_integrator.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "penumbra/render/bsdf.h"
#include "penumbra/render/bsdf_lanes.h"
#include "penumbra/render/media_common.h"

namespace penumbra {
namespace {

constexpr float kInvPi = 0.318309886183790671538f;

inline Lanes LuminanceLanes(const Vec3Lanes& c) {
  return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z;
}

// split-sum specular reflectance, analytic fit (Karis 2014, "Physically based shading on mobile").
inline Eigen::Vector3f EnvBrdfApprox(const Eigen::Vector3f& f0, float n_v, float roughness) {
  const float r0 = roughness * -1.0f + 1.0f;
  const float r1 = roughness * -0.0275f + 0.0425f;
  const float r2 = roughness * -0.572f + 1.04f;
  const float r3 = roughness * 0.022f - 0.04f;
  const float a004 = std::min(r0 * r0, std::exp2(-9.28f * n_v)) * r0 + r1;
  const float a = a004 * -1.04f + r2;
  const float b = a004 * 1.04f + r3;
  return (f0 * a + Eigen::Vector3f::Constant(b)).cwiseMax(0.0f).cwiseMin(1.0f);
}

// per-thread scratch, sized once per light count and reused across tiles and frames.
struct Scratch {
  std::vector<Lanes> u1, u2;              // per light: random numbers of every lane
  std::vector<LightSampleLanes> samples;  // per light
  std::vector<Vec3Lanes> contrib;         // per light: unshadowed f cos E
};

// what the effects do to the radiance L seen through pixel `pixel` along the camera ray:
// the media along the ray attenuate and add to it, and the nearest particle streak is
// alpha-composited over it (render/media_realtime.h, render/particle_scene.h). no random
// numbers here (the froxel volumes are jittered per column when they are built).
Eigen::Vector3f ApplyViewEffects(const FrameContext& ctx, const Ray& ray, bool hit, float t_hit,
                                 int u, int v, Eigen::Vector3f L) {
  const MediaFrame& fx = *ctx.effects;
  const RealtimeMedia* rm = fx.realtime_media();
  const ParticleScene* parts = fx.particles();
  if (rm == nullptr && parts == nullptr) return L;
  const float d_len = ray.d.norm();
  const Eigen::Vector3f d = ray.d / d_len;
  const float inf = std::numeric_limits<float>::infinity();
  const float t_end = hit ? t_hit * d_len : inf;
  if (rm != nullptr) {
    const MediaSegment seg = rm->IntegrateView(*ctx.lights, ray.o, d, t_end, u, v);
    L = seg.T.cwiseProduct(L) + seg.L_add;
  }
  ParticleHit ph;
  if (parts != nullptr && parts->PixelHit(ray, u, v, hit ? t_hit : inf, &ph)) {
    // the streak over what lies behind it: alpha (media to the streak, then the streak) +
    // (1 - alpha) (media to the end, then the surface); equal to compositing at the streak.
    const float t_p = ph.t * d_len;
    Eigen::Vector3f Lp = parts->Shade(ph, ray.o + t_p * d, *ctx.lights, fx.sky_ambient());
    if (rm != nullptr) {
      const MediaSegment front = rm->IntegrateView(*ctx.lights, ray.o, d, t_p, u, v);
      Lp = front.T.cwiseProduct(Lp) + front.L_add;
    }
    L = ph.alpha * Lp + (1.0f - ph.alpha) * L;
  }
  return L;
}

}  // namespace

int64_t RealtimeIntegrator::RenderTile(const FrameContext& ctx, const PrimaryHits& primary,
                                       const FrameBuffers& out) const {
  thread_local Scratch scratch;
  const PixelTile& tile = primary.tile;
  const int n = tile.width * tile.height;
  const int num_lights = ctx.lights->size();
  scratch.u1.resize(num_lights);
  scratch.u2.resize(num_lights);
  scratch.samples.resize(num_lights);
  scratch.contrib.resize(num_lights);
  int64_t traced = 0;
  const uint64_t frame_key = ctx.FrameKey();
  const uint64_t width = static_cast<uint64_t>(ctx.camera->width());
  const MediaFrame* fx = ctx.effects;
  const RealtimeMedia* rm = fx != nullptr ? fx->realtime_media() : nullptr;
  const float wetness = fx != nullptr ? fx->surface_wetness() : 0.0f;
  // the effects on the pixels of a run whose surface radiance is final (misses hold the sky).
  auto finish_run = [&](int i0, int m, const LaneMask& hit, const Vec3Lanes& L) {
    for (int k = 0; k < m; ++k) {
      const int i = i0 + k;
      const int u = tile.x0 + i % tile.width, v = tile.y0 + i / tile.width;
      float* Lp = out.radiance->at(u, v);
      const Eigen::Vector3f Ls = hit[k] ? L.Lane(k) : Eigen::Vector3f(Lp[0], Lp[1], Lp[2]);
      const Eigen::Vector3f Lf =
          ApplyViewEffects(ctx, primary.rays[i], hit[k], primary.hits[i].t, u, v, Ls);
      Lp[0] = Lf.x(), Lp[1] = Lf.y(), Lp[2] = Lf.z();
    }
  };

  // runs of kLanes pixels (a full tile row): per-pixel set-up, then every light for
  // all lanes at once, its shadow rays as one Embree packet.
  for (int i0 = 0; i0 < n; i0 += kLanes) {
    const int m = std::min(kLanes, n - i0);
    LaneMask hit = LaneMask::Constant(false);
    BsdfLanes bsdf;
    Vec3Lanes p, origin, L;
    for (int k = 0; k < kLanes; ++k) {
      const int i = i0 + k;
      const bool lane_hit = k < m && primary.did_hit[i];
      hit[k] = lane_hit;
      if (!lane_hit) {
        // harmless values for idle lanes: every lane computes every light.
        const Eigen::Vector3f z = Eigen::Vector3f::UnitZ();
        p.Set(k, Eigen::Vector3f::Zero());
        origin.Set(k, Eigen::Vector3f::Zero());
        L.Set(k, Eigen::Vector3f::Zero());
        bsdf.n.Set(k, z), bsdf.ng.Set(k, z), bsdf.wo.Set(k, z);
        bsdf.n_v[k] = 1, bsdf.a2[k] = 1;
        bsdf.c_diff.Set(k, Eigen::Vector3f::Zero()), bsdf.f0.Set(k, Eigen::Vector3f::Zero());
        for (int j = 0; j < num_lights; ++j) scratch.u1[j][k] = scratch.u2[j][k] = 0.5f;
        if (k < m) {
          const int u = tile.x0 + i % tile.width, v = tile.y0 + i / tile.width;
          const Eigen::Vector3f sky = ctx.sky->Radiance(primary.rays[i].d.normalized());
          float* Lp = out.radiance->at(u, v);
          Lp[0] = sky.x(), Lp[1] = sky.y(), Lp[2] = sky.z();
          if (out.albedo) std::fill_n(out.albedo->at(u, v), 3, 0.0f);
          if (out.normal) std::fill_n(out.normal->at(u, v), 3, 0.0f);
        }
        continue;
      }
      const int u = tile.x0 + i % tile.width, v = tile.y0 + i / tile.width;
      const SurfaceHit& h = primary.hits[i];
      SurfaceMaterial mat = ctx.materials->Evaluate(h);
      if (wetness > 0) ApplySurfaceWetness(wetness, h.ns_W, &mat.pbr);
      const Eigen::Vector3f wo = -primary.rays[i].d.normalized();
      const BrdfCoefficients coef = BrdfCoefficients::From(mat.pbr);
      bsdf.Set(k, coef, h.ns_W, h.ng_W, wo);
      const Eigen::Vector3f n_s = bsdf.n.Lane(k);
      p.Set(k, h.p_W);
      // shadow rays start off the surface on the lit side (lights behind it contribute 0).
      origin.Set(k, OffsetRayOrigin(h.p_W, h.ng_W));

      // emission and sky ambient (occluded by the static geometry when there is a sky volume).
      const Eigen::Vector3f spec =
          EnvBrdfApprox(coef.f0, std::max(bsdf.n_v[k], 0.0f), mat.pbr.roughness);
      const Eigen::Vector3f reflect =
          coef.c_diff.cwiseProduct(Eigen::Vector3f::Ones() - spec) + spec;
      const Eigen::Vector3f sky_E = ctx.sky_volume != nullptr
                                        ? ctx.sky_volume->Irradiance(h.p_W, n_s, *ctx.sky)
                                        : ctx.sky->Irradiance(n_s);
      L.Set(k, mat.emission + (sky_E * kInvPi).cwiseProduct(reflect));

      Rng rng(FrameContext::PixelStream(frame_key, static_cast<uint64_t>(v) * width + u, 0));
      for (int j = 0; j < num_lights; ++j) {
        scratch.u1[j][k] = rng.Uniform();
        scratch.u2[j][k] = rng.Uniform();
      }
      if (out.albedo) {
        float* a = out.albedo->at(u, v);
        a[0] = mat.pbr.base_color.x(), a[1] = mat.pbr.base_color.y(), a[2] = mat.pbr.base_color.z();
      }
      if (out.normal) {
        float* nn = out.normal->at(u, v);
        nn[0] = n_s.x(), nn[1] = n_s.y(), nn[2] = n_s.z();
      }
    }
    if (!hit.any()) {
      if (fx != nullptr) finish_run(i0, m, hit, L);
      continue;
    }

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
      ctx.lights->SampleLanes(j, p, scratch.u1[j], scratch.u2[j], &s);
      const Vec3Lanes f = bsdf.Eval(s.wi);
      Vec3Lanes& c = scratch.contrib[j];
      for (int k = 0; k < kLanes; ++k) {
        const bool on = hit[k] && s.valid[k];
        c.x[k] = on ? f.x[k] * s.E.x[k] : 0.0f;
        c.y[k] = on ? f.y[k] * s.E.y[k] : 0.0f;
        c.z[k] = on ? f.z[k] * s.E.z[k] : 0.0f;
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
    // lights in order: negligible or shadowless contributions are added as they are, the
    // others after one packet of shadow rays.
    for (int j = 0; j < num_lights; ++j) {
      const Vec3Lanes& c = scratch.contrib[j];
      const LaneMask lit = LuminanceLanes(c) > 0.0f;
      if (!lit.any()) continue;
      const LaneMask shadowed =
          ctx.lights->lights()[j].cast_shadow
              ? LaneMask(lit && (LuminanceLanes(c) >= kNegligibleLight * total))
              : LaneMask::Constant(false);
      for (int k = 0; k < kLanes; ++k) {
        if (!lit[k] || shadowed[k]) continue;
        L.x[k] += c.x[k], L.y[k] += c.y[k], L.z[k] += c.z[k];
      }
      if (!shadowed.any()) continue;
      const LightSampleLanes& s = scratch.samples[j];
      Lanes tmax;
      for (int k = 0; k < kLanes; ++k)
        tmax[k] = std::isinf(s.distance[k]) ? s.distance[k] : s.distance[k] * (1.0f - 1e-4f);
      LaneMask occluded;
      ctx.scene->OccludedLanes(origin, s.wi, tmax, shadowed, &occluded);
      for (int k = 0; k < kLanes; ++k) {
        if (!shadowed[k]) continue;
        ++traced;
        if (occluded[k]) continue;
        L.x[k] += c.x[k], L.y[k] += c.y[k], L.z[k] += c.z[k];
      }
    }
    for (int k = 0; k < m; ++k) {
      if (!hit[k]) continue;
      const int i = i0 + k;
      float* Lp = out.radiance->at(tile.x0 + i % tile.width, tile.y0 + i / tile.width);
      Lp[0] = L.x[k], Lp[1] = L.y[k], Lp[2] = L.z[k];
    }
    if (fx != nullptr) finish_run(i0, m, hit, L);
  }
  return traced;
}

}  // namespace penumbra
