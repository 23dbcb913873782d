#include "penumbra/render/media_scene.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "penumbra/core/error.h"
#include "penumbra/render/media_common.h"
#include "penumbra/render/media_realtime_math.h"

namespace penumbra {
namespace {

constexpr float kInfF = std::numeric_limits<float>::infinity();

// ray-box overlap by the slab method (Kay and Kajiya 1986) clipped to [t0, t1].
bool SlabInterval(const Eigen::Vector3f& o, const Eigen::Vector3f& d, const Eigen::Vector3f& lo_b,
                  const Eigen::Vector3f& hi_b, float t0, float t1, float* a, float* b) {
  return MediaSlabInterval(o.data(), d.data(), lo_b.data(), hi_b.data(), t0, t1, a, b);
}

void CheckCoefficients(const Eigen::Vector3f& sigma_t, const Eigen::Vector3f& albedo, float g,
                       const std::string& key) {
  if (!sigma_t.allFinite() || sigma_t.minCoeff() < 0)
    throw ConfigError("", 0, key + ".sigma_t_per_m", "expected finite values >= 0 (1/m)");
  if (!albedo.allFinite() || albedo.minCoeff() < 0 || albedo.maxCoeff() > 1)
    throw ConfigError("", 0, key + ".albedo", "expected values in [0, 1]");
  if (!(g > -1 && g < 1)) throw ConfigError("", 0, key + ".g", "expected a value in (-1, 1)");
}

}  // namespace

bool AnalyticMedium::Interval(const Eigen::Vector3f& o, const Eigen::Vector3f& d, float t0,
                              float t1, float* a, float* b) const {
  if (!bounded) {
    if (!(t0 < t1)) return false;
    *a = t0;
    *b = t1;
    return true;
  }
  return SlabInterval(o, d, box_min, box_max, t0, t1, a, b);
}

double AnalyticMedium::DensityIntegral(double oz, double dz, double a, double b) const {
  return MediaDensityIntegral(falloff, base, oz, dz, a, b);
}

double AnalyticMedium::InvertDensityIntegral(double oz, double dz, double a, double b,
                                             double tau) const {
  return MediaInvertDensityIntegral(falloff, base, oz, dz, a, b, tau);
}

MediumPod PodOf(const AnalyticMedium& m) {
  MediumPod pod;
  for (int c = 0; c < 3; ++c) {
    pod.sigma_t[c] = m.sigma_t[c];
    pod.sigma_s[c] = m.sigma_s[c];
    pod.box_min[c] = m.box_min[c];
    pod.box_max[c] = m.box_max[c];
  }
  pod.falloff = m.falloff;
  pod.base = m.base;
  pod.bounded = m.bounded ? 1 : 0;
  return pod;
}

bool GridVolume::TrilinearCell(const Eigen::Vector3f& x_G, int i0[3], int i1[3], float w[3]) const {
  if (std::abs(x_G.x()) > half.x() || std::abs(x_G.y()) > half.y() || std::abs(x_G.z()) > half.z())
    return false;
  const Eigen::Vector3f f =
      (x_G + half).cwiseProduct(voxels_per_m) - Eigen::Vector3f::Constant(0.5f);
  const int n[3] = {nx, ny, nz};
  for (int k = 0; k < 3; ++k) {
    const float c = std::clamp(f[k], 0.0f, static_cast<float>(n[k] - 1));
    i0[k] = std::min(static_cast<int>(c), std::max(n[k] - 2, 0));
    i1[k] = std::min(i0[k] + 1, n[k] - 1);
    w[k] = c - static_cast<float>(i0[k]);
  }
  return true;
}

float GridVolume::DensityAt(const Eigen::Vector3f& x_G) const {
  int i0[3], i1[3];
  float w[3];
  if (!TrilinearCell(x_G, i0, i1, w)) return 0.0f;
  const float* D = density->data();
  auto at = [&](int i, int j, int k) { return D[(static_cast<size_t>(k) * ny + j) * nx + i]; };
  const float c00 = at(i0[0], i0[1], i0[2]) * (1 - w[0]) + at(i1[0], i0[1], i0[2]) * w[0];
  const float c10 = at(i0[0], i1[1], i0[2]) * (1 - w[0]) + at(i1[0], i1[1], i0[2]) * w[0];
  const float c01 = at(i0[0], i0[1], i1[2]) * (1 - w[0]) + at(i1[0], i0[1], i1[2]) * w[0];
  const float c11 = at(i0[0], i1[1], i1[2]) * (1 - w[0]) + at(i1[0], i1[1], i1[2]) * w[0];
  const float c0 = c00 * (1 - w[1]) + c10 * w[1];
  const float c1 = c01 * (1 - w[1]) + c11 * w[1];
  return c0 * (1 - w[2]) + c1 * w[2];
}

Eigen::Vector3f GridVolume::EmissionAt(const Eigen::Vector3f& x_G) const {
  if (!emission) return Eigen::Vector3f::Zero();
  int i0[3], i1[3];
  float w[3];
  if (!TrilinearCell(x_G, i0, i1, w)) return Eigen::Vector3f::Zero();
  const float* E = emission->data();
  Eigen::Vector3f sum = Eigen::Vector3f::Zero();
  for (int c = 0; c < 8; ++c) {
    const int i = c & 1 ? i1[0] : i0[0], j = c & 2 ? i1[1] : i0[1], k = c & 4 ? i1[2] : i0[2];
    const float wt =
        (c & 1 ? w[0] : 1 - w[0]) * (c & 2 ? w[1] : 1 - w[1]) * (c & 4 ? w[2] : 1 - w[2]);
    const float* e = E + ((static_cast<size_t>(k) * ny + j) * nx + i) * 3;
    sum += wt * Eigen::Vector3f(e[0], e[1], e[2]);
  }
  return sum;
}

bool GridVolume::Interval(const Eigen::Vector3f& o, const Eigen::Vector3f& d, float t0, float t1,
                          float* a, float* b) const {
  return SlabInterval(ToGrid(o), R_GW * d, -half, half, t0, t1, a, b);
}

float MediumPoint::Phase(float cos_theta) const {
  float sum = 0, wsum = 0;
  for (int i = 0; i < lobes; ++i) {
    sum += weight[i] * HenyeyGreenstein(cos_theta, g[i]);
    wsum += weight[i];
  }
  return wsum > 0 ? sum / wsum : kInv4Pi;
}

Eigen::Vector3f MediumPoint::SamplePhase(const Eigen::Vector3f& wo, float u0, float u1, float u2,
                                         float* pdf) const {
  float wsum = 0;
  for (int i = 0; i < lobes; ++i) wsum += weight[i];
  int pick = 0;
  float acc = 0;
  for (int i = 0; i < lobes; ++i) {
    acc += weight[i];
    pick = i;
    if (u0 * wsum < acc) break;
  }
  float lobe_pdf;
  const Eigen::Vector3f wi =
      SampleHenyeyGreenstein(wo, lobes > 0 ? g[pick] : 0.0f, u1, u2, &lobe_pdf);
  *pdf = lobes > 1 ? Phase(wo.dot(wi)) : lobe_pdf;
  return wi;
}

void MediaScene::Build(const EffectsFrame* fx) {
  analytic_.clear();
  pods_.clear();
  grids_.clear();
  if (fx == nullptr) return;
  for (size_t i = 0; i < fx->homogeneous_media.size(); ++i) {
    const HomogeneousMedium& h = fx->homogeneous_media[i];
    const std::string key = "effects.homogeneous_media[" + std::to_string(i) + "]";
    CheckCoefficients(h.sigma_t_per_m, h.albedo, h.g, key);
    if (!(h.height_falloff_per_m >= 0) || !std::isfinite(h.height_falloff_per_m))
      throw ConfigError("", 0, key + ".height_falloff_per_m", "expected a finite value >= 0");
    AnalyticMedium m;
    m.sigma_t = h.sigma_t_per_m;
    m.sigma_s = h.sigma_t_per_m.cwiseProduct(h.albedo);
    m.g = h.g;
    m.falloff = h.height_falloff_per_m;
    m.base = h.base_height_m;
    if (h.region) {
      m.bounded = true;
      m.box_min = h.region->min_W.cast<float>();
      m.box_max = h.region->max_W.cast<float>();
      if (!(m.box_min.array() <= m.box_max.array()).all())
        throw ConfigError("", 0, key + ".region", "expected min_W <= max_W per axis");
    } else if (std::isfinite(h.layer_top_m)) {
      // a layer of fog: unbounded in x, y and downwards, up to its top (docs/effects.md).
      m.bounded = true;
      m.box_min = Eigen::Vector3f::Constant(-kInfF);
      m.box_max = Eigen::Vector3f(kInfF, kInfF, h.layer_top_m);
    }
    m.sigma_bar = m.sigma_t.maxCoeff();
    if (m.sigma_bar > 0) {
      analytic_.push_back(m);
      pods_.push_back(PodOf(m));
    }
  }
  for (size_t i = 0; i < fx->grid_media.size(); ++i) {
    const GridMedium& gm = fx->grid_media[i];
    const std::string key = "effects.grid_media[" + std::to_string(i) + "]";
    CheckCoefficients(gm.sigma_t_per_m, gm.albedo, gm.g, key);
    if (gm.nx < 1 || gm.ny < 1 || gm.nz < 1)
      throw ConfigError("", 0, key + ".nx", "expected nx, ny, nz >= 1");
    const size_t cells = static_cast<size_t>(gm.nx) * gm.ny * gm.nz;
    if (!gm.density || gm.density->size() != cells)
      throw ConfigError("", 0, key + ".density",
                        "expected nx * ny * nz = " + std::to_string(cells) + " values");
    if (gm.emission && gm.emission->size() != 3 * cells)
      throw ConfigError("", 0, key + ".emission",
                        "expected nx * ny * nz * 3 = " + std::to_string(3 * cells) + " values");
    if (!(gm.half_extents_m.array() > 0).all())
      throw ConfigError("", 0, key + ".half_extents_m", "expected values > 0 m");
    GridVolume v;
    const Eigen::Matrix3d R_WG = gm.X_WG.linear();
    v.R_GW = R_WG.transpose().cast<float>();
    v.p_GW = (-(R_WG.transpose() * gm.X_WG.translation())).cast<float>();
    v.half = gm.half_extents_m.cast<float>();
    v.nx = gm.nx, v.ny = gm.ny, v.nz = gm.nz;
    v.voxels_per_m = Eigen::Vector3f(gm.nx / (2 * v.half.x()), gm.ny / (2 * v.half.y()),
                                     gm.nz / (2 * v.half.z()));
    v.density = gm.density;
    v.emission = gm.emission;
    v.sigma_t = gm.sigma_t_per_m;
    v.sigma_s = gm.sigma_t_per_m.cwiseProduct(gm.albedo);
    v.g = gm.g;
    float mx = 0;
    for (float x : *gm.density) {
      if (!(x >= 0) || !std::isfinite(x))
        throw ConfigError("", 0, key + ".density", "expected finite values >= 0");
      mx = std::max(mx, x);
    }
    v.max_density = mx;
    v.majorant = v.sigma_t.maxCoeff() * mx;
    bool emissive = false;
    if (gm.emission)
      for (float x : *gm.emission) {
        if (!(x >= 0) || !std::isfinite(x))
          throw ConfigError("", 0, key + ".emission", "expected finite values >= 0");
        emissive = emissive || x > 0;
      }
    if (!emissive) v.emission.reset();
    // an emissive grid needs collisions even where it does not attenuate: at least a few
    // tentative collisions per box crossing.
    if (emissive) v.majorant = std::max(v.majorant, 4.0f / v.half.minCoeff());
    if (v.majorant > 0) grids_.push_back(std::move(v));
  }
}

Eigen::Vector3f MediaScene::AnalyticOpticalDepth(const Eigen::Vector3f& o, const Eigen::Vector3f& d,
                                                 float t0, float t1) const {
  const Float3 tau = AnalyticOpticalDepthOf(pods_.data(), static_cast<int>(pods_.size()), o.data(),
                                            d.data(), t0, t1);
  return {tau.x, tau.y, tau.z};
}

MediumPoint MediaScene::At(const Eigen::Vector3f& p) const {
  MediumPoint mp;
  auto add_lobe = [&](float w, float g) {
    if (!(w > 0)) return;
    for (int i = 0; i < mp.lobes; ++i)
      if (mp.g[i] == g) {
        mp.weight[i] += w;
        return;
      }
    if (mp.lobes < MediumPoint::kMaxLobes) {
      mp.weight[mp.lobes] = w;
      mp.g[mp.lobes] = g;
      ++mp.lobes;
    } else {
      mp.weight[mp.lobes - 1] += w;  // more lobes than kept: the last one absorbs the rest
    }
  };
  for (const AnalyticMedium& m : analytic_) {
    if (m.bounded &&
        ((p.array() < m.box_min.array()).any() || (p.array() > m.box_max.array()).any()))
      continue;
    const float h = m.Density(p.z());
    mp.sigma_t += h * m.sigma_t;
    mp.sigma_s += h * m.sigma_s;
    mp.sigma_bar += h * m.sigma_bar;
    add_lobe(h * Mean3(m.sigma_s), m.g);
  }
  for (const GridVolume& v : grids_) {
    const Eigen::Vector3f x = v.ToGrid(p);
    if (std::abs(x.x()) > v.half.x() || std::abs(x.y()) > v.half.y() ||
        std::abs(x.z()) > v.half.z())
      continue;
    const float dens = v.DensityAt(x);
    mp.sigma_t += dens * v.sigma_t;
    mp.sigma_s += dens * v.sigma_s;
    mp.sigma_bar += v.majorant;
    if (v.emission) mp.emission += v.EmissionAt(x);
    add_lobe(dens * Mean3(v.sigma_s), v.g);
  }
  return mp;
}

Eigen::Vector3f MediaScene::Transmittance(const Eigen::Vector3f& o, const Eigen::Vector3f& d,
                                          float t0, float t1, Rng* rng) const {
  Eigen::Vector3f T = (-AnalyticOpticalDepth(o, d, t0, t1)).array().exp().matrix();
  for (const GridVolume& v : grids_) {
    if (!(T.maxCoeff() > 0)) return Eigen::Vector3f::Zero();
    float a, b;
    if (!v.Interval(o, d, t0, t1, &a, &b)) continue;
    const float inv_maj = 1.0f / v.majorant;
    const Eigen::Vector3f d_G = v.R_GW * d, o_G = v.ToGrid(o);
    float t = a;
    for (;;) {
      t -= std::log(1.0f - rng->Uniform()) * inv_maj;
      if (t >= b) break;
      const float dens = v.DensityAt(o_G + t * d_G);
      T = T.cwiseProduct((Eigen::Vector3f::Ones() - dens * inv_maj * v.sigma_t).cwiseMax(0.0f));
      // Russian roulette on small estimates keeps long dense crossings cheap (unbiased).
      const float m = T.maxCoeff();
      if (m < 0.05f) {
        if (!(m > 0) || rng->Uniform() >= 0.5f) return Eigen::Vector3f::Zero();
        T *= 2.0f;
      }
    }
  }
  return T;
}

TrackEvent MediaScene::Track(const Eigen::Vector3f& o, const Eigen::Vector3f& d, float t0, float t1,
                             Rng* rng, Eigen::Vector3f* beta, Eigen::Vector3f* L, float* t_out,
                             MediumPoint* mp_out) const {
  float t = t0;
  for (;;) {
    // the next tentative collision: the earliest sample of every medium's majorant process.
    float t_next = kInfF;
    for (const AnalyticMedium& m : analytic_) {
      float a, b;
      if (!m.Interval(o, d, t, std::min(t1, t_next), &a, &b)) continue;
      const double tau = -std::log(1.0 - rng->UniformD()) / m.sigma_bar;
      const double tt = m.InvertDensityIntegral(o.z(), d.z(), a, b, tau);
      if (tt < t_next) t_next = static_cast<float>(tt);
    }
    for (const GridVolume& v : grids_) {
      float a, b;
      if (!v.Interval(o, d, t, std::min(t1, t_next), &a, &b)) continue;
      const float tt = a - std::log(1.0f - rng->Uniform()) / v.majorant;
      if (tt < b && tt < t_next) t_next = tt;
    }
    if (!(t_next < t1)) return TrackEvent::kNone;
    // guard against a collision that does not advance (float rounding at huge t).
    t = std::max(t_next, std::nextafter(t, kInfF));
    const MediumPoint mp = At(o + t * d);
    if (!(mp.sigma_bar > 0)) continue;
    if (mp.emission.maxCoeff() > 0) *L += beta->cwiseProduct(mp.emission) / mp.sigma_bar;
    const Eigen::Vector3f sigma_a = (mp.sigma_t - mp.sigma_s).cwiseMax(0.0f);
    const Eigen::Vector3f sigma_n =
        (Eigen::Vector3f::Constant(mp.sigma_bar) - mp.sigma_t).cwiseMax(0.0f);
    const float pa = Mean3(beta->cwiseProduct(sigma_a));
    const float ps = Mean3(beta->cwiseProduct(mp.sigma_s));
    const float pn = Mean3(beta->cwiseProduct(sigma_n));
    const float sum = pa + ps + pn;
    if (!(sum > 0)) {
      *beta = Eigen::Vector3f::Zero();
      return TrackEvent::kAbsorb;
    }
    const float u = rng->Uniform() * sum;
    if (u < pa) {
      *beta = Eigen::Vector3f::Zero();
      return TrackEvent::kAbsorb;
    }
    if (u < pa + ps) {
      *beta = beta->cwiseProduct(mp.sigma_s) * (sum / (mp.sigma_bar * ps));
      *t_out = t;
      *mp_out = mp;
      return TrackEvent::kScatter;
    }
    *beta = beta->cwiseProduct(sigma_n) * (sum / (mp.sigma_bar * pn));
  }
}

}  // namespace penumbra
