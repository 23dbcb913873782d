#include "penumbra/render/media/media_scene.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "penumbra/core/error.h"
#include "penumbra/render/media/media_common.h"
#include "penumbra/render/media/media_realtime_math.h"

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
  return MediaGridCell(pod, x_G.data(), i0, i1, w);
}

float GridVolume::DensityAt(const Eigen::Vector3f& x_G) const {
  return MediaGridDensity(pod, x_G.data());
}

Eigen::Vector3f GridVolume::EmissionAt(const Eigen::Vector3f& x_G) const {
  const Float3 e = MediaGridEmission(pod, x_G.data());
  return {e.x, e.y, e.z};
}

bool GridVolume::Interval(const Eigen::Vector3f& o, const Eigen::Vector3f& d, float t0, float t1,
                          float* a, float* b) const {
  return MediaGridInterval(pod, o.data(), d.data(), t0, t1, a, b);
}

Eigen::Vector3f MediumPoint::SamplePhase(const Eigen::Vector3f& wo, float u0, float u1, float u2,
                                         float* pdf) const {
  const Float3 wi = MediaSamplePhase(*this, Float3{wo.x(), wo.y(), wo.z()}, u0, u1, u2, pdf);
  return {wi.x, wi.y, wi.z};
}

void MediaScene::Build(const EffectsFrame* fx) {
  analytic_.clear();
  pods_.clear();
  terms_.clear();
  grids_.clear();
  grid_pods_.clear();
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
      terms_.push_back(MediumTracePod{m.g, m.sigma_bar});
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
    if (v.majorant > 0) {
      MediaGridPod& p = v.pod;
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) p.box.R_GW[3 * r + c] = v.R_GW(r, c);
        p.box.p_GW[r] = v.p_GW[r];
        p.box.half[r] = v.half[r];
        p.voxels_per_m[r] = v.voxels_per_m[r];
        p.sigma_t[r] = v.sigma_t[r];
        p.sigma_s[r] = v.sigma_s[r];
      }
      p.n[0] = v.nx, p.n[1] = v.ny, p.n[2] = v.nz;
      p.density = v.density->data();
      p.emission = v.emission ? v.emission->data() : nullptr;
      p.g = v.g;
      p.max_density = v.max_density;
      p.majorant = v.majorant;
      grid_pods_.push_back(p);
      grids_.push_back(std::move(v));
    }
  }
}

MediaSceneView MediaScene::View() const {
  MediaSceneView s;
  s.media = pods_.data();
  s.terms = terms_.data();
  s.num_media = static_cast<int>(pods_.size());
  s.grids = grid_pods_.data();
  s.num_grids = static_cast<int>(grid_pods_.size());
  return s;
}

Eigen::Vector3f MediaScene::AnalyticOpticalDepth(const Eigen::Vector3f& o, const Eigen::Vector3f& d,
                                                 float t0, float t1) const {
  const Float3 tau = AnalyticOpticalDepthOf(pods_.data(), static_cast<int>(pods_.size()), o.data(),
                                            d.data(), t0, t1);
  return {tau.x, tau.y, tau.z};
}

MediumPoint MediaScene::At(const Eigen::Vector3f& p) const {
  MediumPoint mp;
  static_cast<MediumPointPod&>(mp) = MediaPointAt(View(), p.data());
  return mp;
}

Eigen::Vector3f MediaScene::Transmittance(const Eigen::Vector3f& o, const Eigen::Vector3f& d,
                                          float t0, float t1, Rng* rng) const {
  const Float3 T = MediaTransmittanceOf(View(), o.data(), d.data(), t0, t1, rng);
  return {T.x, T.y, T.z};
}

TrackEvent MediaScene::Track(const Eigen::Vector3f& o, const Eigen::Vector3f& d, float t0, float t1,
                             Rng* rng, Eigen::Vector3f* beta, Eigen::Vector3f* L, float* t_out,
                             MediumPoint* mp_out) const {
  Float3 b{beta->x(), beta->y(), beta->z()}, l{L->x(), L->y(), L->z()};
  const TrackEvent ev =
      MediaTrackOf(View(), o.data(), d.data(), t0, t1, rng, &b, &l, t_out, mp_out);
  *beta = Eigen::Vector3f(b.x, b.y, b.z);
  *L = Eigen::Vector3f(l.x, l.y, l.z);
  return ev;
}

}  // namespace penumbra
