#include "penumbra/render/realtime_integrator.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "penumbra/render/bsdf.h"

namespace penumbra {
namespace {

constexpr float kInvPi = 0.318309886183790671538f;

inline float Luminance(const Eigen::Vector3f& c) {
  return 0.2126f * c.x() + 0.7152f * c.y() + 0.0722f * c.z();
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

// a light contribution waiting for its shadow ray.
struct PendingShadow {
  int pixel;              // index within the tile
  Eigen::Vector3f value;  // added if unoccluded
};

// shadow rays of one tile towards one light.
struct ShadowBatch {
  std::vector<Ray> rays;
  std::vector<PendingShadow> pending;
};

// per-thread scratch, grown once and reused across tiles and frames.
struct Scratch {
  std::vector<ShadowBatch> batches;  // per light
  std::unique_ptr<bool[]> occluded;
  int occluded_capacity = 0;
  std::vector<Eigen::Vector3f> contrib;
  std::vector<LightSample> samples;
  std::vector<uint8_t> valid;
};

}  // namespace

int64_t RealtimeIntegrator::RenderTile(const FrameContext& ctx, const PrimaryHits& primary,
                                       const FrameBuffers& out) const {
  thread_local Scratch scratch;
  const PixelTile& tile = primary.tile;
  const int n = tile.width * tile.height;
  const int num_lights = ctx.lights->size();
  if (static_cast<int>(scratch.batches.size()) < num_lights) scratch.batches.resize(num_lights);
  for (int j = 0; j < num_lights; ++j) {
    scratch.batches[j].rays.clear();
    scratch.batches[j].pending.clear();
  }
  scratch.contrib.resize(num_lights);
  scratch.samples.resize(num_lights);
  scratch.valid.resize(num_lights);

  for (int i = 0; i < n; ++i) {
    const int u = tile.x0 + i % tile.width, v = tile.y0 + i / tile.width;
    float* L = out.radiance->at(u, v);
    const Ray& ray = primary.rays[i];
    if (!primary.did_hit[i]) {
      const Eigen::Vector3f sky = ctx.sky->Radiance(ray.d.normalized());
      L[0] = sky.x(), L[1] = sky.y(), L[2] = sky.z();
      if (out.albedo) std::fill_n(out.albedo->at(u, v), 3, 0.0f);
      if (out.normal) std::fill_n(out.normal->at(u, v), 3, 0.0f);
      continue;
    }
    const SurfaceHit& hit = primary.hits[i];
    const SurfaceMaterial mat = ctx.materials->Evaluate(hit);
    const Eigen::Vector3f wo = -ray.d.normalized();
    const Bsdf bsdf(mat.pbr, hit.ns_W, hit.ng_W, wo);
    const Eigen::Vector3f& n_s = bsdf.shading_normal();

    // emission and unoccluded sky ambient.
    const Eigen::Vector3f spec =
        EnvBrdfApprox(bsdf.f0(), std::max(n_s.dot(wo), 0.0f), mat.pbr.roughness);
    const Eigen::Vector3f reflect =
        bsdf.diffuse_color().cwiseProduct(Eigen::Vector3f::Ones() - spec) + spec;
    Eigen::Vector3f radiance =
        mat.emission + (ctx.sky->Irradiance(n_s) * kInvPi).cwiseProduct(reflect);

    // one sample per light; the unshadowed total decides which shadow rays are worth tracing.
    Rng rng(ctx.PixelStream(u, v, 0));
    float total = Luminance(radiance);
    for (int j = 0; j < num_lights; ++j) {
      const float u1 = rng.Uniform(), u2 = rng.Uniform();
      LightSample& s = scratch.samples[j];
      scratch.valid[j] = 0;
      if (!ctx.lights->Sample(j, hit.p_W, u1, u2, &s)) continue;
      const Eigen::Vector3f f = bsdf.Eval(s.wi);
      if (!(f.maxCoeff() > 0)) continue;
      scratch.contrib[j] = f.cwiseProduct(s.E);
      scratch.valid[j] = 1;
      total += Luminance(scratch.contrib[j]);
    }
    for (int j = 0; j < num_lights; ++j) {
      if (!scratch.valid[j]) continue;
      const LightSample& s = scratch.samples[j];
      if (!s.cast_shadow || Luminance(scratch.contrib[j]) < kNegligibleLight * total) {
        radiance += scratch.contrib[j];
        continue;
      }
      Ray r = SpawnRay(hit, s.wi);
      r.tmax = std::isinf(s.distance) ? s.distance : s.distance * (1.0f - 1e-4f);
      scratch.batches[j].rays.push_back(r);
      scratch.batches[j].pending.push_back({i, scratch.contrib[j]});
    }
    L[0] = radiance.x(), L[1] = radiance.y(), L[2] = radiance.z();
    if (out.albedo) {
      float* a = out.albedo->at(u, v);
      a[0] = mat.pbr.base_color.x(), a[1] = mat.pbr.base_color.y(), a[2] = mat.pbr.base_color.z();
    }
    if (out.normal) {
      float* nn = out.normal->at(u, v);
      nn[0] = n_s.x(), nn[1] = n_s.y(), nn[2] = n_s.z();
    }
  }

  // the tile's shadow rays towards each light as one coherent stream; contributions are added
  // in light order, so each pixel's sum is independent of scheduling.
  int64_t traced = 0;
  for (int j = 0; j < num_lights; ++j) {
    ShadowBatch& batch = scratch.batches[j];
    const int m = static_cast<int>(batch.rays.size());
    if (m == 0) continue;
    if (scratch.occluded_capacity < m) {
      scratch.occluded = std::make_unique<bool[]>(m);
      scratch.occluded_capacity = m;
    }
    ctx.scene->OccludedMany(batch.rays.data(), m, nullptr, scratch.occluded.get(),
                            /*coherent=*/true);
    for (int k = 0; k < m; ++k) {
      if (scratch.occluded[k]) continue;
      const PendingShadow& p = batch.pending[k];
      float* L = out.radiance->at(tile.x0 + p.pixel % tile.width, tile.y0 + p.pixel / tile.width);
      L[0] += p.value.x(), L[1] += p.value.y(), L[2] += p.value.z();
    }
    traced += m;
  }
  return traced;
}

}  // namespace penumbra
