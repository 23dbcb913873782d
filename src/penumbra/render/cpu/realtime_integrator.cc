#include "penumbra/render/cpu/realtime_integrator.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "penumbra/render/brdf_math.h"
#include "penumbra/render/bsdf.h"
#include "penumbra/render/cpu/bsdf_lanes.h"
#include "penumbra/render/media_common.h"

namespace penumbra {
namespace {

constexpr float kInvPi = 0.318309886183790671538f;

inline Lanes LuminanceLanes(const Vec3Lanes& c) { return pbm::Luminance709(c.x, c.y, c.z); }

// the split-sum ambient specular fit (render/brdf_math.h) for one shading point.
inline Eigen::Vector3f EnvBrdfApproxScalar(const Eigen::Vector3f& f0, float n_v, float roughness) {
  const Float3 s = EnvBrdfApprox<float, Float3>(Float3{f0.x(), f0.y(), f0.z()}, n_v, roughness);
  return Eigen::Vector3f(s.x, s.y, s.z);
}

// radiance arriving along a mirrored ray `ray` (the mirror layer, SurfaceMaterial::mirror):
// the sky where it escapes, else the surface it hits shaded as the tier shades what the camera
// sees (emission, sky ambient, one sample of every light with a shadow ray), the light samples'
// numbers from draws first_draw ... of the pixel's `stream`. one reflection: a mirror seen in a
// mirror shows its BRDF only. `path_m`: the camera-to-mirror distance (texture level of detail);
// no media or particles along the mirrored ray.
Eigen::Vector3f MirrorRadiance(const FrameContext& ctx, const Ray& ray, float path_m, float wetness,
                               uint64_t stream, uint64_t first_draw, int64_t* traced) {
  SurfaceHit h;
  ++*traced;
  const Eigen::Vector3f d = ray.d.normalized();
  if (!ctx.scene->Intersect(ray, &h)) return ctx.sky->Radiance(d);
  const Eigen::Vector3f wo = -d;
  const TextureFootprint footprint =
      ConeFootprint(ctx.camera->pixel_spread_rad(), path_m + h.t * ray.d.norm(), d, h);
  SurfaceMaterial mat = ctx.materials->EvaluateAndMapNormal(&h, footprint);
  if (wetness > 0) ApplySurfaceWetness(wetness, h.ns_W, &mat.pbr);
  const Bsdf bsdf(mat.pbr, h.ns_W, h.ng_W, wo);
  const Eigen::Vector3f& n = bsdf.shading_normal();
  const Eigen::Vector3f sky_E = ctx.sky_volume != nullptr
                                    ? ctx.sky_volume->Irradiance(h.p_W, n, *ctx.sky)
                                    : ctx.sky->Irradiance(n);
  const Eigen::Vector3f spec = EnvBrdfApproxScalar(bsdf.f0(), std::max(n.dot(wo), 0.0f),
                                                   std::clamp(mat.pbr.roughness, 0.0f, 1.0f));
  const Eigen::Vector3f reflect =
      bsdf.diffuse_color().cwiseProduct(Eigen::Vector3f::Ones() - spec) + spec;
  Eigen::Vector3f L = mat.emission + (sky_E * (kInvPi * mat.occlusion)).cwiseProduct(reflect);
  const Eigen::Vector3f origin = OffsetRayOrigin(h.p_W, h.ng_W);
  for (int j = 0; j < ctx.lights->size(); ++j) {
    float u1, u2;
    Rng::Uniform2Of(Rng::DrawAt(stream, first_draw + j), &u1, &u2);
    LightSample s;
    if (!ctx.lights->Sample(j, h.p_W, u1, u2, &s)) continue;
    const Eigen::Vector3f c = bsdf.Eval(s.wi).cwiseProduct(s.E);
    if (!(c.maxCoeff() > 0)) continue;
    if (s.cast_shadow) {
      Ray sr;
      sr.o = origin;
      sr.d = s.wi;
      sr.tmax = s.distance * (1.0f - 1e-4f);  // +inf stays +inf
      ++*traced;
      if (ctx.scene->Occluded(sr)) continue;
    }
    L += c;
  }
  return L;
}

// per-thread scratch, sized once per light count and reused across tiles and frames.
struct Scratch {
  std::vector<Lanes> u1, u2;              // per light: random numbers of every lane
  std::vector<LightSampleLanes> samples;  // per light
  std::vector<Vec3Lanes> contrib;         // per light: unshadowed f cos E
  std::vector<Eigen::Vector3f> wo;        // per tile pixel: unit direction towards the camera
  std::vector<Eigen::Vector3f> n_s;       // per tile pixel: usable shading normal
  std::vector<Eigen::Vector3f> sky_E;     // per tile pixel: sky irradiance on n_s
};

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
  const float max_extent = 0.25f * volume->spacing();
  constexpr float kPlaneTolM = 1e-3f;
  SkyIrradianceVolume::ShBlend blend;
  auto shared = [&](int, int, const int* quad) {
    const int i00 = quad[0];
    for (int c = 0; c < 4; ++c) {
      const int i = quad[c];
      if (!(primary.did_hit[i] && primary.hits[i].geom == primary.hits[i00].geom &&
            primary.hits[i].ng_W == primary.hits[i00].ng_W))
        return false;
    }
    const Eigen::Vector3f& n0 = primary.hits[i00].ng_W;
    const Eigen::Vector3f& p0 = primary.hits[i00].p_W;
    Eigen::Vector3f mean = Eigen::Vector3f::Zero();
    for (int c = 0; c < 4; ++c) {
      const Eigen::Vector3f dp = primary.hits[quad[c]].p_W - p0;
      if (!(std::abs(n0.dot(dp)) <= kPlaneTolM && dp.cwiseAbs().maxCoeff() <= max_extent))
        return false;
      mean += 0.25f * primary.hits[quad[c]].p_W;
    }
    volume->Blend(mean, n0, &blend);
    for (int c = 0; c < 4; ++c)
      scratch->sky_E[quad[c]] = volume->IrradianceAt(blend, scratch->n_s[quad[c]], *ctx.sky);
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
// alpha-composited over it (render/cpu/media_realtime.h, render/embree/particle_scene.h). no random
// numbers here (the froxel volumes are jittered per column when they are built). `quad`: the
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
    L = ph.alpha * Lp + (1.0f - ph.alpha) * L;
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
  scratch.u1.resize(num_lights);
  scratch.u2.resize(num_lights);
  scratch.samples.resize(num_lights);
  scratch.contrib.resize(num_lights);
  TileSkyIrradiance(ctx, primary, &scratch);
  int64_t traced = 0;
  const uint64_t frame_key = ctx.FrameKey();
  const uint64_t width = static_cast<uint64_t>(ctx.camera->width());
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
    float mirror[kLanes] = {};  // SurfaceMaterial::mirror of every lane
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
          const Eigen::Vector3f sky = ctx.sky->Radiance(primary.rays[i].d.normalized());
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
      mirror[k] = mat.mirror;
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
    // random numbers: light j's (u1, u2) from the top 48 bits of draw j of the pixel's stream,
    // as Rng::Uniform2 takes them; computed for every lane at once (idle lanes' values are
    // never used).
    {
      alignas(64) uint64_t stream[kLanes];
      for (int k = 0; k < kLanes; ++k)
        stream[k] = static_cast<uint64_t>(lane_v[k]) * width + static_cast<uint64_t>(lane_u[k]);
      for (int k = 0; k < kLanes; ++k)
        stream[k] = FrameContext::PixelStream(frame_key, stream[k], 0);
      for (int j = 0; j < num_lights; ++j) {
        float* u1 = scratch.u1[j].data();
        float* u2 = scratch.u2[j].data();
        for (int k = 0; k < kLanes; ++k) Rng::Uniform2Of(Rng::DrawAt(stream[k], j), &u1[k], &u2[k]);
      }
    }
    bsdf.SetCoefficients(pbr);

    // emission and sky ambient, E_sky / pi (c_diff (1 - S) + S).
    {
      const Vec3Lanes spec =
          EnvBrdfApprox<Lanes, Vec3Lanes>(bsdf.f0, bsdf.n_v.max(0.0f), pbr.roughness);
      const Vec3Lanes reflect{bsdf.c_diff.x * (1.0f - spec.x) + spec.x,
                              bsdf.c_diff.y * (1.0f - spec.y) + spec.y,
                              bsdf.c_diff.z * (1.0f - spec.z) + spec.z};
      L = {emission.x + (sky_E.x * kInvPi) * reflect.x, emission.y + (sky_E.y * kInvPi) * reflect.y,
           emission.z + (sky_E.z * kInvPi) * reflect.z};
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
      Vec3Lanes& c = scratch.contrib[j];
      ctx.lights->SampleLanes(j, p, scratch.u1[j], scratch.u2[j], &s);
      const Vec3Lanes f = bsdf.Eval(s.wi);
      const LaneMask on = hit && s.valid;
      c = Where(on, Vec3Lanes{f.x * s.E.x, f.y * s.E.y, f.z * s.E.z});
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
      const LaneMask lit = GreaterThan(LuminanceLanes(c), 0.0f);
      if (!lit.any()) continue;
      const LaneMask shadowed =
          ctx.lights->lights()[j].cast_shadow
              ? lit && GreaterEqual(LuminanceLanes(c), kNegligibleLight * total)
              : LaneMask::Constant(false);
      const LaneMask unshadowed = lit && !shadowed;
      L = L + Where(unshadowed, c);
      if (!shadowed.any()) continue;
      const LightSampleLanes& s = scratch.samples[j];
      const Lanes tmax = s.distance * (1.0f - 1e-4f);  // +inf stays +inf
      LaneMask occluded;
      ctx.scene->OccludedLanes(origin, s.wi, tmax, shadowed, &occluded);
      traced += shadowed.count();
      const LaneMask visible = shadowed && !occluded;
      L = L + Where(visible, c);
    }
    for (int k = 0; k < m; ++k) {
      if (!hit[k]) continue;
      Eigen::Vector3f Lk(L.x[k], L.y[k], L.z[k]);
      if (mirror[k] > 0) {
        // the mirror layer: (1 - r) L + r L_mirror, its light samples after this pixel's.
        const int i = i0 + k;
        const SurfaceHit& h = primary.hits[i];
        const Eigen::Vector3f d = primary.rays[i].d.normalized();
        const Eigen::Vector3f wi = d - 2.0f * d.dot(h.ng_W) * h.ng_W;
        const uint64_t stream = FrameContext::PixelStream(
            frame_key, static_cast<uint64_t>(lane_v[k]) * width + static_cast<uint64_t>(lane_u[k]),
            0);
        const Eigen::Vector3f Lm =
            MirrorRadiance(ctx, SpawnRay(h, wi), h.t * primary.rays[i].d.norm(), wetness, stream,
                           static_cast<uint64_t>(num_lights), &traced);
        Lk = (1.0f - mirror[k]) * Lk + mirror[k] * Lm;
      }
      float* Lp = out.radiance->at(lane_u[k], lane_v[k]);
      Lp[0] = Lk.x(), Lp[1] = Lk.y(), Lp[2] = Lk.z();
    }
  }
  // the effects once every pixel of the tile holds its surface or sky radiance.
  if (fx != nullptr) ApplyTileViewEffects(ctx, primary, out);
  return traced;
}

}  // namespace penumbra
