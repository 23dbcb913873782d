#include "penumbra/render/cpu/mirror_layer.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "penumbra/render/light/brdf_math.h"
#include "penumbra/render/light/bsdf.h"
#include "penumbra/render/media/media_common.h"

namespace penumbra {
namespace {

// the split-sum ambient specular fit (render/light/brdf_math.h) for one shading point.
Eigen::Vector3f EnvBrdfApproxScalar(const Eigen::Vector3f& f0, float n_v, float roughness) {
  const Float3 s = EnvBrdfApprox<float, Float3>(Float3{f0.x(), f0.y(), f0.z()}, n_v, roughness);
  return Eigen::Vector3f(s.x, s.y, s.z);
}

}  // namespace

Eigen::Vector3f MirrorRadiance(const FrameContext& ctx, const Ray& ray, float path_m, float wetness,
                               uint64_t stream, uint64_t first_draw, int64_t* traced) {
  SurfaceHit h;
  ++*traced;
  const Eigen::Vector3f d = ray.d.normalized();
  if (!ctx.scene->Intersect(ray, &h)) return ctx.sky->Background(d);
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
  Eigen::Vector3f L = mat.emission + (sky_E * (pbm::kInvPi * mat.occlusion)).cwiseProduct(reflect);
  const Eigen::Vector3f origin = OffsetRayOrigin(h.p_W, h.ng_W);
  const bool shadows = ctx.ablation == nullptr || ctx.ablation->shadows;
  for (int j = 0; j < ctx.lights->size(); ++j) {
    float u1, u2;
    Rng::Uniform2Of(Rng::DrawAt(stream, first_draw + j), &u1, &u2);
    LightSample s;
    if (!ctx.lights->Sample(j, h.p_W, u1, u2, &s)) continue;
    const Eigen::Vector3f c = bsdf.Eval(s.wi).cwiseProduct(s.E);
    if (!(c.maxCoeff() > 0)) continue;
    if (s.cast_shadow && shadows) {
      Ray sr;
      sr.o = origin;
      sr.d = s.wi;
      sr.tmax = s.distance * (1.0f - 1e-4f);  // +inf stays +inf
      // a sun ray that a static box provably blocks is occluded without tracing it.
      if (ctx.sun_occluders != nullptr && j == ctx.sun_occluders->light_index() &&
          ctx.sun_occluders->Blocks(sr.o, sr.d))
        continue;
      ++*traced;
      if (ctx.scene->Occluded(sr)) continue;
    }
    L += c;
  }
  return L;
}

int64_t ApplyMirrorLayer(const FrameContext& ctx, const PrimaryHits& primary, const float* mirror,
                         float wetness, const FrameBuffers& out) {
  const PixelTile& tile = primary.tile;
  const int w = tile.width, n = tile.width * tile.height;
  const uint64_t frame_key = ctx.FrameKey();
  const uint64_t width = static_cast<uint64_t>(ctx.camera->width());
  const uint64_t first_draw = static_cast<uint64_t>(ctx.lights->size());
  const bool sparse_on = ctx.ablation == nullptr || ctx.ablation->mirror_sparse;
  thread_local std::vector<Eigen::Vector3f> Lm;
  thread_local std::vector<char> traced_here;
  Lm.resize(n);
  traced_here.assign(n, 0);
  int64_t traced = 0;
  auto trace = [&](int i) {
    const int u = tile.x0 + i % w, v = tile.y0 + i / w;
    const SurfaceHit& h = primary.hits[i];
    const Eigen::Vector3f d = primary.rays[i].d.normalized();
    const Eigen::Vector3f wi = d - 2.0f * d.dot(h.ng_W) * h.ng_W;
    const uint64_t stream = FrameContext::PixelStream(
        frame_key, static_cast<uint64_t>(v) * width + static_cast<uint64_t>(u), 0);
    return MirrorRadiance(ctx, SpawnRay(h, wi), h.t * primary.rays[i].d.norm(), wetness, stream,
                          first_draw, &traced);
  };
  // the grid step of pixel i's layer: 1 (every pixel), 2 or 4 (file comment).
  auto step = [&](int i) { return sparse_on ? MirrorGridStep(mirror[i]) : 1; };
  // the traced pixels: those on their layer's grid (tiles start at multiples of 16, so the
  // tile's grid is the image's).
  for (int i = 0; i < n; ++i) {
    if (!(mirror[i] > 0)) continue;
    const int x = i % w, y = i / w, s = step(i);
    if (x % s == 0 && y % s == 0) {
      Lm[i] = trace(i);
      traced_here[i] = 1;
    }
  }
  // the others: bilinear over the traced grid pixels around them on the same face and grid.
  for (int i = 0; i < n; ++i) {
    if (!(mirror[i] > 0) || traced_here[i]) continue;
    const int x = i % w, y = i / w, s = step(i);
    const SurfaceHit& h = primary.hits[i];
    const int gx = x - x % s, gy = y - y % s;
    const int xs[2] = {gx, gx + s}, ys[2] = {gy, gy + s};
    const float wx[2] = {MirrorGridWeight(x % s, s, 0), MirrorGridWeight(x % s, s, 1)};
    const float wy[2] = {MirrorGridWeight(y % s, s, 0), MirrorGridWeight(y % s, s, 1)};
    Eigen::Vector3f acc = Eigen::Vector3f::Zero();
    float wsum = 0;
    for (int b = 0; b < 2; ++b) {
      if (!(wy[b] > 0) || ys[b] >= tile.height) continue;
      for (int a = 0; a < 2; ++a) {
        if (!(wx[a] > 0) || xs[a] >= w) continue;
        const int j = ys[b] * w + xs[a];
        if (!traced_here[j] || !(mirror[j] > 0) || step(j) != s) continue;
        const SurfaceHit& hj = primary.hits[j];
        if (hj.geom != h.geom || hj.ng_W != h.ng_W) continue;
        const float wgt = wx[a] * wy[b];
        acc += wgt * Lm[j];
        wsum += wgt;
      }
    }
    Lm[i] = wsum > 0 ? Eigen::Vector3f(acc / wsum) : trace(i);
  }
  for (int i = 0; i < n; ++i) {
    if (!(mirror[i] > 0)) continue;
    float* Lp = out.radiance->at(tile.x0 + i % w, tile.y0 + i / w);
    const float r = mirror[i];
    for (int c = 0; c < 3; ++c) Lp[c] = MirrorBlend(Lp[c], Lm[i][c], r);
  }
  return traced;
}

}  // namespace penumbra
