#include "penumbra/render/cpu/mirror_layer.h"

#include <vector>

#include "penumbra/render/light/bsdf.h"
#include "penumbra/render/media/media_common.h"
#include "penumbra/render/transport/realtime_mirror.h"

namespace penumbra {
namespace {

Float3 ToF3Of(const Eigen::Vector3f& v) { return Float3{v.x(), v.y(), v.z()}; }

}  // namespace

Eigen::Vector3f MirrorRadiance(const FrameContext& ctx, const Ray& ray, float path_m, float wetness,
                               uint64_t stream, int64_t* traced) {
  SurfaceHit h;
  ++*traced;
  const Eigen::Vector3f d = ray.d.normalized();
  if (!ctx.scene->Intersect(ray, &h)) return ctx.sky->Background(d);
  const Eigen::Vector3f wo = -d;
  const TextureFootprint footprint =
      ConeFootprint(ctx.camera->pixel_spread_rad(), path_m + h.t * ray.d.norm(), d, h);
  SurfaceMaterial mat = ctx.materials->EvaluateAndMapNormal(&h, footprint);
  if (wetness > 0) ApplySurfaceWetness(wetness, h.ns_W, &mat.pbr);
  // the hit as the transport's shading point (render/transport/realtime_mirror.h).
  cuda::ShadingPoint sp;
  const Eigen::Vector3f n = UsableShadingNormal(h.ns_W, h.ng_W, wo);
  sp.p = ToF3Of(h.p_W);
  sp.ng = ToF3Of(h.ng_W);
  sp.n = ToF3Of(n);
  sp.wo = ToF3Of(wo);
  sp.base = ToF3Of(mat.pbr.base_color);
  sp.emission = ToF3Of(mat.emission);
  sp.roughness = mat.pbr.roughness;
  sp.metallic = mat.pbr.metallic;
  sp.specular = mat.pbr.specular;
  sp.occlusion = mat.occlusion;
  const Eigen::Vector3f sky_E = ctx.sky_volume != nullptr
                                    ? ctx.sky_volume->Irradiance(h.p_W, n, *ctx.sky)
                                    : ctx.sky->Irradiance(n);
  const bool shadows = ctx.ablation == nullptr || ctx.ablation->shadows;
  // the shadow rays through Embree; a sun ray that a static box provably blocks is occluded
  // without tracing it.
  auto occluded = [&](int j, const cuda::TraceRay& r) {
    Ray sr;
    sr.o = Eigen::Vector3f(r.o.x, r.o.y, r.o.z);
    sr.d = Eigen::Vector3f(r.d.x, r.d.y, r.d.z);
    sr.tmax = r.tmax;
    if (ctx.sun_occluders != nullptr && j == ctx.sun_occluders->light_index() &&
        ctx.sun_occluders->Blocks(sr.o, sr.d))
      return true;
    ++*traced;
    return ctx.scene->Occluded(sr);
  };
  const Float3 L = cuda::MirrorHitRadiance(sp, ToF3Of(sky_E), ctx.lights->pods().data(),
                                           ctx.lights->size(), stream, shadows, occluded);
  return Eigen::Vector3f(L.x, L.y, L.z);
}

int64_t ShadeMirrorLayerTile(const FrameContext& ctx, const PrimaryHits& primary,
                             const float* mirror, float wetness, const FrameBuffers& out) {
  const PixelTile& tile = primary.tile;
  const int w = tile.width, n = tile.width * tile.height;
  const uint64_t frame_key = ctx.FrameKey();
  const uint64_t width = static_cast<uint64_t>(ctx.camera->width());
  const bool sparse_on = ctx.ablation == nullptr || ctx.ablation->mirror_sparse;
  thread_local std::vector<Float3> Lm;
  thread_local std::vector<char> traced_here;
  Lm.resize(n);
  traced_here.assign(n, 0);
  int64_t traced = 0;
  auto trace = [&](int i) {
    const int u = tile.x0 + i % w, v = tile.y0 + i / w;
    const SurfaceHit& h = primary.hits[i];
    const Eigen::Vector3f d = primary.rays[i].d.normalized();
    const cuda::TraceRay r = cuda::MirroredRay(ToF3Of(d), ToF3Of(h.p_W), ToF3Of(h.ng_W));
    Ray ray;
    ray.o = Eigen::Vector3f(r.o.x, r.o.y, r.o.z);
    ray.d = Eigen::Vector3f(r.d.x, r.d.y, r.d.z);
    const uint64_t stream = FrameContext::PixelStream(
        frame_key, static_cast<uint64_t>(v) * width + static_cast<uint64_t>(u), 0);
    return ToF3Of(
        MirrorRadiance(ctx, ray, h.t * primary.rays[i].d.norm(), wetness, stream, &traced));
  };
  // the grid step of pixel i's layer: 1 (every pixel), 2 or 4 (mirror_math.h).
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
  // the others: the mean of the traced grid pixels around them on the same face and grid.
  for (int i = 0; i < n; ++i) {
    if (!(mirror[i] > 0) || traced_here[i]) continue;
    const int s = step(i);
    const SurfaceHit& h = primary.hits[i];
    auto lends = [&](int x, int y) {
      const int j = y * w + x;
      return traced_here[j] && mirror[j] > 0 && step(j) == s && primary.hits[j].geom == h.geom &&
             primary.hits[j].ng_W == h.ng_W;
    };
    int lx[4], ly[4];
    float wgt[4];
    const int count = cuda::MirrorGridLenders(i % w, i / w, s, w, tile.height, lends, lx, ly, wgt);
    Lm[i] = count > 0
                ? cuda::MirrorGridMean(count, wgt, [&](int k) { return Lm[ly[k] * w + lx[k]]; })
                : trace(i);
  }
  for (int i = 0; i < n; ++i) {
    if (!(mirror[i] > 0)) continue;
    float* Lp = out.radiance->at(tile.x0 + i % w, tile.y0 + i / w);
    const Float3 L = cuda::MirrorLayerBlend(Float3{Lp[0], Lp[1], Lp[2]}, Lm[i], mirror[i]);
    Lp[0] = L.x, Lp[1] = L.y, Lp[2] = L.z;
  }
  return traced;
}

}  // namespace penumbra
