#include "penumbra/render/realtime_integrator.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "penumbra/render/bsdf.h"
#include "penumbra/render/bsdf_lanes.h"

namespace penumbra {
namespace {

constexpr float kInvPi = 0.318309886183790671538f;
constexpr float kInfinity = std::numeric_limits<float>::infinity();

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

// key of the frame's interleaved-sampling pattern (HashKeys(frame key, kSkyPatternKey)).
constexpr uint64_t kSkyPatternKey = 0x5c1e5ca1ab1eull;
// the plane-distance tolerance of the sky filter, in pixel footprints.
constexpr float kPlaneTolerancePixels = 2.0f;

// an orthonormal basis (t, b, n) around unit n without branches on a threshold (Duff et al.,
// "Building an orthonormal basis, revisited", JCGT 2017).
inline void Basis(const Eigen::Vector3f& n, Eigen::Vector3f* t, Eigen::Vector3f* b) {
  const float sign = std::copysign(1.0f, n.z());
  const float a = -1.0f / (sign + n.z());
  const float c = n.x() * n.y() * a;
  *t = {1.0f + sign * n.x() * n.x() * a, sign * c, -sign * n.x()};
  *b = {c, sign + n.y() * n.y() * a, -n.y()};
}

// interleaved sampling over kSkyBlock x kSkyBlock pixel blocks: kSkyBlock^2 strata.
constexpr int kSkyBlock = 8;
// the sky filter: a tent of 2 kSkyRadius + 1 taps per axis, weight kSkyBlock - |offset|, so
// that every residue mod kSkyBlock (every stratum column / row) gets the same total weight.
constexpr int kSkyRadius = kSkyBlock - 1;
constexpr float TapWeight(int k) {
  return static_cast<float>(kSkyBlock - (k < kSkyRadius ? kSkyRadius - k : k - kSkyRadius));
}

// the sky filter's planes: structure-of-arrays fields of a padded frame (kSkyRadius rows and
// columns of zeros around it, width rounded up to kLanes), so that the passes run over
// kLanes pixels at once without bounds checks. a zero normal marks "no surface" (weight 0).
enum SkyField { kNx, kNy, kNz, kPx, kPy, kPz, kInvTol, kNum, kDen, kHNum, kHDen, kNumFields };

// the filter's centre pixels: kLanes consecutive pixels starting at padded index i.
struct Centre {
  Lanes nx, ny, nz, px, py, pz, inv_tol;
  Centre(const float* const* f, size_t i) {
    using Map = Eigen::Map<const Lanes, Eigen::Unaligned>;
    nx = Map(f[kNx] + i), ny = Map(f[kNy] + i), nz = Map(f[kNz] + i);
    px = Map(f[kPx] + i), py = Map(f[kPy] + i), pz = Map(f[kPz] + i);
    inv_tol = Map(f[kInvTol] + i);
  }
};

// geometry weights of kLanes taps j for the centres c: (n_i . n_j)^4 (0 if negative) times
// a tent in the distance of p_j from the tangent plane of p_i, in units of i's tolerance.
inline Lanes GeometryWeight(const Centre& c, const float* const* f, size_t j) {
  using Map = Eigen::Map<const Lanes, Eigen::Unaligned>;
  const Lanes cos =
      (c.nx * Map(f[kNx] + j) + c.ny * Map(f[kNy] + j) + c.nz * Map(f[kNz] + j)).max(0.0f);
  const Lanes dist = (c.nx * (Map(f[kPx] + j) - c.px) + c.ny * (Map(f[kPy] + j) - c.py) +
                      c.nz * (Map(f[kPz] + j) - c.pz))
                         .abs();
  const Lanes c2 = cos * cos;
  return c2 * c2 * (1.0f - dist * c.inv_tol).max(0.0f);
}

// per-thread scratch, sized once per light count and reused across tiles and frames.
struct Scratch {
  std::vector<Lanes> u1, u2;              // per light: random numbers of every lane
  std::vector<LightSampleLanes> samples;  // per light
  std::vector<Vec3Lanes> contrib;         // per light: unshadowed f cos E
};

}  // namespace

void RealtimeIntegrator::BeginFrame(const FrameContext& ctx) {
  if (width_ == ctx.camera->width() && height_ == ctx.camera->height()) return;
  width_ = ctx.camera->width();
  height_ = ctx.camera->height();
  {
    taps_.assign(static_cast<size_t>(width_) * height_, SkyTap());
    padded_width_ = (width_ + kLanes - 1) / kLanes * kLanes + 2 * kSkyRadius;
    padded_size_ = static_cast<size_t>(padded_width_) * (height_ + 2 * kSkyRadius);
    planes_.assign(kNumFields * padded_size_, 0.0f);
  }
}

void RealtimeIntegrator::EndFrame(const FrameContext& ctx, const FrameBuffers& out,
                                  ThreadPool* pool) {
  (void)ctx;
  const int W = width_, H = height_, PW = padded_width_;
  const float* f[kNumFields];
  float* fw[kNumFields];
  for (int k = 0; k < kNumFields; ++k) f[k] = fw[k] = planes_.data() + k * padded_size_;
  auto padded = [&](int u, int v) {
    return static_cast<size_t>(v + kSkyRadius) * PW + static_cast<size_t>(u + kSkyRadius);
  };
  // structure-of-arrays copy of the taps (the padding stays zero).
  pool->ParallelFor(H, [&](int64_t vv) {
    const int v = static_cast<int>(vv);
    for (int u = 0; u < W; ++u) {
      const SkyTap& t = taps_[static_cast<size_t>(v) * W + u];
      const size_t i = padded(u, v);
      const bool ok = t.tol > 0;
      fw[kNx][i] = ok ? t.n.x() : 0.0f, fw[kNy][i] = ok ? t.n.y() : 0.0f;
      fw[kNz][i] = ok ? t.n.z() : 0.0f;
      fw[kPx][i] = t.p.x(), fw[kPy][i] = t.p.y(), fw[kPz][i] = t.p.z();
      fw[kInvTol][i] = ok ? 1.0f / t.tol : 0.0f;
      fw[kNum][i] = t.num, fw[kDen][i] = t.den;
    }
  });
  using Map = Eigen::Map<const Lanes, Eigen::Unaligned>;
  // horizontal pass: (HNum, HDen) = sums over the row's taps, weighted for the centre.
  pool->ParallelFor(H, [&](int64_t vv) {
    const int v = static_cast<int>(vv);
    for (int u0 = 0; u0 < W; u0 += kLanes) {
      const size_t i = padded(u0, v);
      const Centre c(f, i);
      Lanes num = Lanes::Zero(), den = Lanes::Zero();
      for (int k = 0; k <= 2 * kSkyRadius; ++k) {
        const size_t j = i + k - kSkyRadius;
        const Lanes w = TapWeight(k) * GeometryWeight(c, f, j);
        num += w * Map(f[kNum] + j);
        den += w * Map(f[kDen] + j);
      }
      Eigen::Map<Lanes, Eigen::Unaligned>(fw[kHNum] + i) = num;
      Eigen::Map<Lanes, Eigen::Unaligned>(fw[kHDen] + i) = den;
    }
  });
  // vertical pass: the ratio of the column sums, times the unoccluded sky ambient.
  pool->ParallelFor(H, [&](int64_t vv) {
    const int v = static_cast<int>(vv);
    for (int u0 = 0; u0 < W; u0 += kLanes) {
      const size_t i = padded(u0, v);
      const Centre c(f, i);
      Lanes num = Lanes::Zero(), den = Lanes::Zero();
      for (int k = 0; k <= 2 * kSkyRadius; ++k) {
        const size_t j = i + (static_cast<size_t>(k) - kSkyRadius) * PW;
        const Lanes w = TapWeight(k) * GeometryWeight(c, f, j);
        num += w * Map(f[kHNum] + j);
        den += w * Map(f[kHDen] + j);
      }
      const Lanes vis = (den > 0.0f).select((num / den.max(1e-30f)).min(1.0f), 0.0f);
      const int m = std::min(kLanes, W - u0);
      for (int k = 0; k < m; ++k) {
        const SkyTap& c = taps_[static_cast<size_t>(v) * W + u0 + k];
        if (!(c.tol > 0)) continue;
        float* L = out.radiance->at(u0 + k, v);
        L[0] += c.weight.x() * vis[k], L[1] += c.weight.y() * vis[k], L[2] += c.weight.z() * vis[k];
      }
    }
  });
}

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
  // the frame's interleaved-sampling pattern: a permutation of the strata (xor with a key)
  // and a toroidal shift of the grid.
  constexpr int kStrata = kSkyBlock * kSkyBlock;
  Rng pattern_rng(HashKeys(frame_key, kSkyPatternKey));
  const int stratum_xor = static_cast<int>(pattern_rng.Uniform() * kStrata) & (kStrata - 1);
  const float shift1 = pattern_rng.Uniform(), shift2 = pattern_rng.Uniform();
  const float inv_fx = 1.0f / static_cast<float>(ctx.camera->intrinsics().fx);

  // runs of kLanes pixels (a full tile row): per-pixel set-up, then every light for
  // all lanes at once, its shadow rays as one Embree packet.
  for (int i0 = 0; i0 < n; i0 += kLanes) {
    const int m = std::min(kLanes, n - i0);
    LaneMask hit = LaneMask::Constant(false);
    BsdfLanes bsdf;
    Vec3Lanes p, origin, L, sky_dir, reflect_l;
    LaneMask above = LaneMask::Constant(false);
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
        sky_dir.Set(k, z), reflect_l.Set(k, Eigen::Vector3f::Zero());
        if (k < m) {
          const int u = tile.x0 + i % tile.width, v = tile.y0 + i / tile.width;
          taps_[static_cast<size_t>(v) * width + u] = SkyTap();
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
      const SurfaceMaterial mat = ctx.materials->Evaluate(h);
      const Eigen::Vector3f wo = -primary.rays[i].d.normalized();
      const BrdfCoefficients coef = BrdfCoefficients::From(mat.pbr);
      bsdf.Set(k, coef, h.ns_W, h.ng_W, wo);
      const Eigen::Vector3f n_s = bsdf.n.Lane(k);
      p.Set(k, h.p_W);
      // shadow rays start off the surface on the lit side (lights behind it contribute 0).
      origin.Set(k, OffsetRayOrigin(h.p_W, h.ng_W));

      // emission and unoccluded sky ambient.
      const Eigen::Vector3f spec =
          EnvBrdfApprox(coef.f0, std::max(bsdf.n_v[k], 0.0f), mat.pbr.roughness);
      const Eigen::Vector3f reflect =
          coef.c_diff.cwiseProduct(Eigen::Vector3f::Ones() - spec) + spec;
      reflect_l.Set(k, reflect);
      L.Set(k, mat.emission);

      // the sky ray: the stratum of the pixel within its block, cosine-weighted about n_s
      // (its sky luminance and the irradiance are looked up for the whole run below).
      const uint64_t pixel = static_cast<uint64_t>(v) * width + u;
      SkyTap& tap = taps_[pixel];
      tap.n = n_s;
      tap.p = h.p_W;
      tap.tol = kPlaneTolerancePixels * std::max(h.t, 1e-6f) * inv_fx;
      {
        const int stratum = ((u % kSkyBlock) + kSkyBlock * (v % kSkyBlock)) ^ stratum_xor;
        constexpr float kInvBlock = 1.0f / kSkyBlock;
        float s1 = (stratum % kSkyBlock) * kInvBlock + shift1;
        float s2 = (stratum / kSkyBlock) * kInvBlock + shift2;
        s1 -= std::floor(s1), s2 -= std::floor(s2);
        float sn, cs;
        SinCos2Pi(std::min(s2, 0.99999994f), &sn, &cs);
        const float r = std::sqrt(s1);
        Eigen::Vector3f t, b;
        Basis(n_s, &t, &b);
        const Eigen::Vector3f d =
            (t * (r * cs) + b * (r * sn) + n_s * std::sqrt(std::max(1.0f - s1, 0.0f))).normalized();
        sky_dir.Set(k, d);
        above[k] = d.dot(h.ng_W) > 0;
      }

      Rng rng(FrameContext::PixelStream(frame_key, pixel, 0));
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
    if (!hit.any()) continue;

    // unoccluded sky ambient (the filter's weight at V = 1) and sky luminance of the rays; a
    // ray is traced where both are non-zero and it leaves above the geometric surface.
    Vec3Lanes E;
    ctx.sky->IrradianceLanes(bsdf.n, &E);
    const Lanes sky_y = ctx.sky->LuminanceLookupLanes(sky_dir);
    LaneMask sky_ray = LaneMask::Constant(false);
    for (int k = 0; k < m; ++k) {
      if (!hit[k]) continue;
      const int i = i0 + k;
      SkyTap& tap =
          taps_[static_cast<size_t>(tile.y0 + i / tile.width) * width + tile.x0 + i % tile.width];
      tap.weight = (E.Lane(k) * kInvPi).cwiseProduct(reflect_l.Lane(k));
      const bool lit = tap.weight != Eigen::Vector3f::Zero();
      tap.num = 0;
      tap.den = lit ? sky_y[k] : 0.0f;
      sky_ray[k] = lit && above[k] && tap.den > 0;
    }

    // the sky rays of the run, as one packet.
    if (sky_ray.any()) {
      LaneMask occluded;
      ctx.scene->OccludedLanes(origin, sky_dir, Lanes::Constant(kInfinity), sky_ray, &occluded);
      for (int k = 0; k < m; ++k) {
        if (!sky_ray[k]) continue;
        ++traced;
        const int i = i0 + k;
        SkyTap& tap =
            taps_[static_cast<size_t>(tile.y0 + i / tile.width) * width + tile.x0 + i % tile.width];
        if (!occluded[k]) tap.num = tap.den;
      }
    }

    // one sample per light; the unshadowed total (with the unoccluded sky) decides which
    // shadow rays are worth tracing.
    Lanes total = LuminanceLanes(L);
    for (int k = 0; k < m; ++k) {
      if (!hit[k]) continue;
      const int i = i0 + k;
      const SkyTap& tap =
          taps_[static_cast<size_t>(tile.y0 + i / tile.width) * width + tile.x0 + i % tile.width];
      total[k] += 0.2126f * tap.weight.x() + 0.7152f * tap.weight.y() + 0.0722f * tap.weight.z();
    }
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
  }
  return traced;
}

}  // namespace penumbra
