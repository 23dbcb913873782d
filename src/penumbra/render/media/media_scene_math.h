#pragma once
// the pathtraced tier's media formulas (render/media/media_scene.h) as PB_HOST_DEVICE functions
// over plain data (docs/gpu.md, "One shading code"): the CPU's MediaScene builds a MediaSceneView
// over its own arrays and its members call these (At, Transmittance, Track, MediumPoint's Phase
// and SamplePhase, GridVolume's DensityAt / EmissionAt / Interval), and the CUDA backend's path
// kernels (render/transport/path_trace.h) call the same definitions over device copies of the
// arrays.
//  - SampleHenyeyGreensteinDir: the Henyey-Greenstein phase function's sampling (render/
//    media_common.h's SampleHenyeyGreenstein calls it; the function itself is MediaPhaseHG);
//  - MediumHeightDensity: a homogeneous medium's relative density at a height
//    (AnalyticMedium::Density);
//  - MediaGridPod, MediaGridCell / MediaGridDensity / MediaGridEmission / MediaGridInterval: a
//    voxel grid's trilinear lookups and box interval (GridVolume's);
//  - MediumPointPod, MediaPointAt, MediaPhase, MediaSamplePhase: the coefficients and phase
//    mixture of all media at a point (MediaScene::At, MediumPoint);
//  - MediaTransmittanceOf: exact transmittance of the homogeneous media times ratio tracking in
//    the grids (MediaScene::Transmittance); MediaTrackOf: spectral delta tracking of a free
//    flight (MediaScene::Track). models and sources: render/media_scene.h.
// operation order: the Eigen code's (per coefficient, its 3x3 product as GridToFrame, its
// maxCoeff as max(max(x, y), z);
// docs/journal/2026-11-27-gpu-pathtraced.md, "Media in the pathtraced tier"),
// and tests/render/media/media_scene_math_test.cc checks the functions bit for bit against Eigen.
// random numbers: the caller's Rng, drawn in the CPU's order.

#include <math.h>
#include <stddef.h>

#include "penumbra/core/exp_rn.h"
#include "penumbra/core/host_device.h"
#include "penumbra/core/rng.h"
#include "penumbra/render/light/bsdf_math.h"
#include "penumbra/render/media/media_realtime_math.h"
#include "penumbra/render/shading_math.h"

namespace penumbra {

// kInv4Pi and the Henyey-Greenstein phase function MediaPhaseHG: render/media_realtime_math.h.

/// samples wi (unit) from the Henyey-Greenstein distribution around wo (unit, pointing back
/// along the incoming ray) with two uniform numbers in [0, 1); *pdf = MediaPhaseHG(
/// dot(wo, wi), g) (PBR 4th ed., eq. 11.17 and SampleHenyeyGreenstein; the orthonormal basis
/// of Duff et al., JCGT 2017).
PB_HOST_DEVICE inline Float3 SampleHenyeyGreensteinDir(const Float3& wo, float g, float u1,
                                                       float u2, float* pdf) {
  // cos of the angle between wi and -wo (the propagation direction).
  float cos_t;
  if (fabsf(g) < 1e-3f) {
    cos_t = 1.0f - 2.0f * u1;
  } else {
    const float s = (1.0f - g * g) / (1.0f + g - 2.0f * g * u1);
    cos_t = (1.0f + g * g - s * s) / (2.0f * g);
  }
  cos_t = pbm::Clamp(cos_t, -1.0f, 1.0f);
  const float sin_t = sqrtf(pbm::Max(0.0f, 1.0f - cos_t * cos_t));
  float sp, cp;
  pbm::SinCos2Pi(u2, &sp, &cp);
  const Float3 w{-wo.x, -wo.y, -wo.z};
  const float sign = w.z >= 0 ? 1.0f : -1.0f;
  const float a = -1.0f / (sign + w.z);
  const float b = w.x * w.y * a;
  const Float3 t{1.0f + sign * w.x * w.x * a, sign * b, -sign * w.x};
  const Float3 bt{b, sign + w.y * w.y * a, -w.y};
  const float kt = sin_t * cp, kb = sin_t * sp;
  const Float3 wi = bsdf_detail::Normalized(Float3{kt * t.x + kb * bt.x + cos_t * w.x,
                                                   kt * t.y + kb * bt.y + cos_t * w.y,
                                                   kt * t.z + kb * bt.z + cos_t * w.z});
  *pdf = MediaPhaseHG(EigenDot(wo, wi), g);
  return wi;
}

/// max(max(x, y), z) as Eigen's maxCoeff.
PB_HOST_DEVICE inline float MediaMax3(const Float3& c) { return pbm::Max(pbm::Max(c.x, c.y), c.z); }

/// the relative density h(z) = exp(-falloff max(0, z - base)) in (0, 1] of a homogeneous medium
/// of height falloff `falloff` (1/m, 0 = uniform) above `base` (m) (AnalyticMedium::Density).
/// kExactExp: the exponential by ExpRn (core/exp_rn.h: the same bits on both processors; the
/// rain streaks' culling, streak_cull_math.h), else expf.
template <bool kExactExp = false>
PB_HOST_DEVICE inline float MediumHeightDensity(float falloff, float base, float z) {
  if (!(falloff > 0 && z > base)) return 1.0f;
  const float x = -falloff * (z - base);
  return kExactExp ? ExpRn(x) : expf(x);
}

/// a homogeneous medium's tracing terms besides its MediumPod (AnalyticMedium's).
struct MediumTracePod {
  float g = 0;          ///< Henyey-Greenstein asymmetry
  float sigma_bar = 0;  ///< majorant rate at full density: max channel of sigma_t, 1/m
};

/// a voxel grid medium (GridVolume) as the shared functions read it. the density (and emission)
/// arrays are the caller's (host or device memory).
struct MediaGridPod {
  /// the world-to-grid transform x_G = R_GW x_W + p_GW and the box half extents (m), read by
  /// GridToFrame / GridRotate (its light-volume fields are unused here)
  GridLightPod box;
  int n[3] = {0, 0, 0};                   ///< nx, ny, nz voxels
  float voxels_per_m[3] = {1, 1, 1};      ///< n / (2 half) per axis
  const float* density = nullptr;         ///< (nz x ny x nx), x fastest
  const float* emission = nullptr;        ///< (nz x ny x nx x 3) cd/m^2 per m, or null
  float sigma_t[3] = {1, 1, 1};           ///< 1/m at density 1
  float sigma_s[3] = {0.9f, 0.9f, 0.9f};  ///< sigma_t * albedo
  float g = 0;                            ///< Henyey-Greenstein asymmetry
  float max_density = 0;                  ///< largest voxel value
  float majorant = 0;                     ///< the grid's majorant rate, 1/m (> 0)
};

/// the voxel-centre cell around grid-frame point x_G (m): lower / upper voxel indices per axis
/// and the trilinear weights of the upper ones (clamped to the outermost voxel centres); false
/// outside the box (GridVolume::TrilinearCell).
PB_HOST_DEVICE inline bool MediaGridCell(const MediaGridPod& v, const float* x_G, int i0[3],
                                         int i1[3], float w[3]) {
  const float* half = v.box.half;
  if (fabsf(x_G[0]) > half[0] || fabsf(x_G[1]) > half[1] || fabsf(x_G[2]) > half[2]) return false;
  for (int k = 0; k < 3; ++k) {
    const float f = (x_G[k] + half[k]) * v.voxels_per_m[k] - 0.5f;
    const float c = pbm::Clamp(f, 0.0f, static_cast<float>(v.n[k] - 1));
    i0[k] = MediaMinI(static_cast<int>(c), MediaMaxI(v.n[k] - 2, 0));
    i1[k] = MediaMinI(i0[k] + 1, v.n[k] - 1);
    w[k] = c - static_cast<float>(i0[k]);
  }
  return true;
}

/// the trilinear density at grid-frame point x_G (0 outside the box; GridVolume::DensityAt).
PB_HOST_DEVICE inline float MediaGridDensity(const MediaGridPod& v, const float* x_G) {
  int i0[3], i1[3];
  float w[3];
  if (!MediaGridCell(v, x_G, i0, i1, w)) return 0.0f;
  const float* D = v.density;
  const size_t nx = static_cast<size_t>(v.n[0]), ny = static_cast<size_t>(v.n[1]);
  auto at = [&](int i, int j, int k) { return D[(static_cast<size_t>(k) * ny + j) * nx + i]; };
  const float c00 = at(i0[0], i0[1], i0[2]) * (1 - w[0]) + at(i1[0], i0[1], i0[2]) * w[0];
  const float c10 = at(i0[0], i1[1], i0[2]) * (1 - w[0]) + at(i1[0], i1[1], i0[2]) * w[0];
  const float c01 = at(i0[0], i0[1], i1[2]) * (1 - w[0]) + at(i1[0], i0[1], i1[2]) * w[0];
  const float c11 = at(i0[0], i1[1], i1[2]) * (1 - w[0]) + at(i1[0], i1[1], i1[2]) * w[0];
  const float c0 = c00 * (1 - w[1]) + c10 * w[1];
  const float c1 = c01 * (1 - w[1]) + c11 * w[1];
  return c0 * (1 - w[2]) + c1 * w[2];
}

/// the trilinear emission (cd/m^2 per m) at grid-frame point x_G: 0 outside the box or without
/// emission (GridVolume::EmissionAt).
PB_HOST_DEVICE inline Float3 MediaGridEmission(const MediaGridPod& v, const float* x_G) {
  Float3 sum{0, 0, 0};
  if (v.emission == nullptr) return sum;
  int i0[3], i1[3];
  float w[3];
  if (!MediaGridCell(v, x_G, i0, i1, w)) return sum;
  const size_t nx = static_cast<size_t>(v.n[0]), ny = static_cast<size_t>(v.n[1]);
  for (int c = 0; c < 8; ++c) {
    const int i = c & 1 ? i1[0] : i0[0], j = c & 2 ? i1[1] : i0[1], k = c & 4 ? i1[2] : i0[2];
    const float wt =
        (c & 1 ? w[0] : 1 - w[0]) * (c & 2 ? w[1] : 1 - w[1]) * (c & 4 ? w[2] : 1 - w[2]);
    const float* e = v.emission + ((static_cast<size_t>(k) * ny + j) * nx + i) * 3;
    sum = Float3{sum.x + wt * e[0], sum.y + wt * e[1], sum.z + wt * e[2]};
  }
  return sum;
}

/// the part [a, b] of [t0, t1] where o + t d (world) is inside the grid's box; false if empty
/// (GridVolume::Interval).
PB_HOST_DEVICE inline bool MediaGridInterval(const MediaGridPod& v, const float* o, const float* d,
                                             float t0, float t1, float* a, float* b) {
  float o_G[3], d_G[3];
  GridToFrame(v.box, o, o_G);
  GridRotate(v.box, d, d_G);
  const float lo[3] = {-v.box.half[0], -v.box.half[1], -v.box.half[2]};
  return MediaSlabInterval(o_G, d_G, lo, v.box.half, t0, t1, a, b);
}

/// a frame's media as the shared functions read them (MediaScene::View on the host; device
/// copies for the path kernels): the homogeneous media (pods and tracing terms, in
/// MediaScene::analytic() order) and the grids (MediaScene::grids() order).
struct MediaSceneView {
  const MediumPod* media = nullptr;
  const MediumTracePod* terms = nullptr;
  int num_media = 0;
  const MediaGridPod* grids = nullptr;
  int num_grids = 0;
};

/// whether `m` holds any medium.
PB_HOST_DEVICE inline bool MediaAny(const MediaSceneView& m) {
  return m.num_media > 0 || m.num_grids > 0;
}

/// the Henyey-Greenstein lobes a medium point keeps (MediumPoint::kMaxLobes).
constexpr int kMediumMaxLobes = 8;

/// the coefficients of all media at one point, with the mixture of their phase functions.
struct MediumPointPod {
  Float3 sigma_t{0, 0, 0}, sigma_s{0, 0, 0};
  Float3 emission{0, 0, 0};  ///< cd/m^2 per m
  float sigma_bar = 0;       ///< the majorant rate at the point (>= max sigma_t)
  int lobes = 0;             ///< Henyey-Greenstein lobes, weight ~ mean sigma_s
  float weight[kMediumMaxLobes] = {0, 0, 0, 0, 0, 0, 0, 0};
  float g[kMediumMaxLobes] = {0, 0, 0, 0, 0, 0, 0, 0};
};

/// adds a lobe of weight w and asymmetry g to mp (merged with a lobe of the same g; beyond
/// kMediumMaxLobes the last lobe absorbs the rest; w <= 0 or NaN: nothing).
PB_HOST_DEVICE inline void MediaAddLobe(MediumPointPod* mp, float w, float g) {
  if (!(w > 0)) return;
  for (int i = 0; i < mp->lobes; ++i)
    if (mp->g[i] == g) {
      mp->weight[i] += w;
      return;
    }
  if (mp->lobes < kMediumMaxLobes) {
    mp->weight[mp->lobes] = w;
    mp->g[mp->lobes] = g;
    ++mp->lobes;
  } else {
    mp->weight[mp->lobes - 1] += w;  // more lobes than kept: the last one absorbs the rest
  }
}

/// all coefficients at world point p (MediaScene::At): per homogeneous medium containing p its
/// coefficients times h(z), per grid whose box holds p its density's and its majorant (and
/// emission), the lobes weighted by the mean sigma_s.
PB_HOST_DEVICE inline MediumPointPod MediaPointAt(const MediaSceneView& s, const float* p) {
  MediumPointPod mp;
  for (int i = 0; i < s.num_media; ++i) {
    const MediumPod& m = s.media[i];
    if (m.bounded != 0 && (p[0] < m.box_min[0] || p[1] < m.box_min[1] || p[2] < m.box_min[2] ||
                           p[0] > m.box_max[0] || p[1] > m.box_max[1] || p[2] > m.box_max[2]))
      continue;
    const float h = MediumHeightDensity(m.falloff, m.base, p[2]);
    mp.sigma_t = Float3{mp.sigma_t.x + h * m.sigma_t[0], mp.sigma_t.y + h * m.sigma_t[1],
                        mp.sigma_t.z + h * m.sigma_t[2]};
    mp.sigma_s = Float3{mp.sigma_s.x + h * m.sigma_s[0], mp.sigma_s.y + h * m.sigma_s[1],
                        mp.sigma_s.z + h * m.sigma_s[2]};
    mp.sigma_bar += h * s.terms[i].sigma_bar;
    MediaAddLobe(&mp, h * MediaMean3(m.sigma_s), s.terms[i].g);
  }
  for (int i = 0; i < s.num_grids; ++i) {
    const MediaGridPod& v = s.grids[i];
    float x[3];
    GridToFrame(v.box, p, x);
    if (fabsf(x[0]) > v.box.half[0] || fabsf(x[1]) > v.box.half[1] || fabsf(x[2]) > v.box.half[2])
      continue;
    const float dens = MediaGridDensity(v, x);
    mp.sigma_t = Float3{mp.sigma_t.x + dens * v.sigma_t[0], mp.sigma_t.y + dens * v.sigma_t[1],
                        mp.sigma_t.z + dens * v.sigma_t[2]};
    mp.sigma_s = Float3{mp.sigma_s.x + dens * v.sigma_s[0], mp.sigma_s.y + dens * v.sigma_s[1],
                        mp.sigma_s.z + dens * v.sigma_s[2]};
    mp.sigma_bar += v.majorant;
    if (v.emission != nullptr) mp.emission = mp.emission + MediaGridEmission(v, x);
    MediaAddLobe(&mp, dens * MediaMean3(v.sigma_s), v.g);
  }
  return mp;
}

/// the mixture phase function sum_i w_i HG(cos_theta, g_i) / sum_i w_i (isotropic without
/// lobes; MediumPoint::Phase).
PB_HOST_DEVICE inline float MediaPhase(const MediumPointPod& mp, float cos_theta) {
  float sum = 0, wsum = 0;
  for (int i = 0; i < mp.lobes; ++i) {
    sum += mp.weight[i] * MediaPhaseHG(cos_theta, mp.g[i]);
    wsum += mp.weight[i];
  }
  return wsum > 0 ? sum / wsum : kInv4Pi;
}

/// samples a lobe with u0, then wi from it (u1, u2); *pdf = MediaPhase(dot(wo, wi))
/// (MediumPoint::SamplePhase).
PB_HOST_DEVICE inline Float3 MediaSamplePhase(const MediumPointPod& mp, const Float3& wo, float u0,
                                              float u1, float u2, float* pdf) {
  float wsum = 0;
  for (int i = 0; i < mp.lobes; ++i) wsum += mp.weight[i];
  int pick = 0;
  float acc = 0;
  for (int i = 0; i < mp.lobes; ++i) {
    acc += mp.weight[i];
    pick = i;
    if (u0 * wsum < acc) break;
  }
  float lobe_pdf;
  const Float3 wi =
      SampleHenyeyGreensteinDir(wo, mp.lobes > 0 ? mp.g[pick] : 0.0f, u1, u2, &lobe_pdf);
  *pdf = mp.lobes > 1 ? MediaPhase(mp, EigenDot(wo, wi)) : lobe_pdf;
  return wi;
}

/// unbiased transmittance estimate along o + t d (d unit), t in [t0, t1] (t1 may be +inf):
/// the homogeneous media's exact e^-tau times ratio tracking inside every grid box, with
/// Russian roulette below 0.05 (draws from rng only inside grid boxes; MediaScene::
/// Transmittance).
PB_HOST_DEVICE inline Float3 MediaTransmittanceOf(const MediaSceneView& s, const float* o,
                                                  const float* d, float t0, float t1, Rng* rng) {
  Float3 T = MediaExpNeg(AnalyticOpticalDepthOf(s.media, s.num_media, o, d, t0, t1), false);
  for (int g = 0; g < s.num_grids; ++g) {
    const MediaGridPod& v = s.grids[g];
    if (!(MediaMax3(T) > 0)) return Float3{0, 0, 0};
    float a, b;
    if (!MediaGridInterval(v, o, d, t0, t1, &a, &b)) continue;
    const float inv_maj = 1.0f / v.majorant;
    float d_G[3], o_G[3];
    GridRotate(v.box, d, d_G);
    GridToFrame(v.box, o, o_G);
    float t = a;
    for (;;) {
      t -= logf(1.0f - rng->Uniform()) * inv_maj;
      if (t >= b) break;
      const float x[3] = {o_G[0] + t * d_G[0], o_G[1] + t * d_G[1], o_G[2] + t * d_G[2]};
      const float k = MediaGridDensity(v, x) * inv_maj;
      T = Float3{T.x * pbm::Max(1.0f - k * v.sigma_t[0], 0.0f),
                 T.y * pbm::Max(1.0f - k * v.sigma_t[1], 0.0f),
                 T.z * pbm::Max(1.0f - k * v.sigma_t[2], 0.0f)};
      // Russian roulette on small estimates keeps long dense crossings cheap (unbiased).
      const float m = MediaMax3(T);
      if (m < 0.05f) {
        if (!(m > 0) || rng->Uniform() >= 0.5f) return Float3{0, 0, 0};
        T = Float3{T.x * 2.0f, T.y * 2.0f, T.z * 2.0f};
      }
    }
  }
  return T;
}

/// outcome of a free flight (MediaTrackOf, MediaScene::Track).
enum class TrackEvent {
  kNone,     ///< the ray reached t1 (throughput reweighted by the null collisions)
  kScatter,  ///< a real scattering event at *t
  kAbsorb,   ///< the path was absorbed (its throughput is 0)
};

/// spectral delta tracking along o + t d (d unit) from t0 to t1 (may be +inf; MediaScene::Track,
/// Kutz et al. 2017 sec. 5.2): adds the emission gathered to *L (times *beta), updates *beta,
/// and on kScatter writes the collision distance *t and the medium there *mp (its sigma_s
/// already folded into *beta).
PB_HOST_DEVICE inline TrackEvent MediaTrackOf(const MediaSceneView& s, const float* o,
                                              const float* d, float t0, float t1, Rng* rng,
                                              Float3* beta, Float3* L, float* t_out,
                                              MediumPointPod* mp_out) {
  float t = t0;
  for (;;) {
    // the next tentative collision: the earliest sample of every medium's majorant process.
    float t_next = INFINITY;
    for (int i = 0; i < s.num_media; ++i) {
      const MediumPod& m = s.media[i];
      float a, b;
      if (!MediumInterval(m, o, d, t, pbm::Min(t1, t_next), &a, &b)) continue;
      const double tau = -log(1.0 - rng->UniformD()) / s.terms[i].sigma_bar;
      const double tt = MediaInvertDensityIntegral(m.falloff, m.base, o[2], d[2], a, b, tau);
      if (tt < t_next) t_next = static_cast<float>(tt);
    }
    for (int i = 0; i < s.num_grids; ++i) {
      const MediaGridPod& v = s.grids[i];
      float a, b;
      if (!MediaGridInterval(v, o, d, t, pbm::Min(t1, t_next), &a, &b)) continue;
      const float tt = a - logf(1.0f - rng->Uniform()) / v.majorant;
      if (tt < b && tt < t_next) t_next = tt;
    }
    if (!(t_next < t1)) return TrackEvent::kNone;
    // guard against a collision that does not advance (float rounding at huge t).
    t = pbm::Max(t_next, nextafterf(t, INFINITY));
    const float p[3] = {o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]};
    const MediumPointPod mp = MediaPointAt(s, p);
    if (!(mp.sigma_bar > 0)) continue;
    const Float3 bt = *beta;
    if (MediaMax3(mp.emission) > 0)
      *L = Float3{L->x + bt.x * mp.emission.x / mp.sigma_bar,
                  L->y + bt.y * mp.emission.y / mp.sigma_bar,
                  L->z + bt.z * mp.emission.z / mp.sigma_bar};
    const Float3 sigma_a{pbm::Max(mp.sigma_t.x - mp.sigma_s.x, 0.0f),
                         pbm::Max(mp.sigma_t.y - mp.sigma_s.y, 0.0f),
                         pbm::Max(mp.sigma_t.z - mp.sigma_s.z, 0.0f)};
    const Float3 sigma_n{pbm::Max(mp.sigma_bar - mp.sigma_t.x, 0.0f),
                         pbm::Max(mp.sigma_bar - mp.sigma_t.y, 0.0f),
                         pbm::Max(mp.sigma_bar - mp.sigma_t.z, 0.0f)};
    const float ba[3] = {bt.x * sigma_a.x, bt.y * sigma_a.y, bt.z * sigma_a.z};
    const float bs[3] = {bt.x * mp.sigma_s.x, bt.y * mp.sigma_s.y, bt.z * mp.sigma_s.z};
    const float bn[3] = {bt.x * sigma_n.x, bt.y * sigma_n.y, bt.z * sigma_n.z};
    const float pa = MediaMean3(ba), ps = MediaMean3(bs), pn = MediaMean3(bn);
    const float sum = pa + ps + pn;
    if (!(sum > 0)) {
      *beta = Float3{0, 0, 0};
      return TrackEvent::kAbsorb;
    }
    const float u = rng->Uniform() * sum;
    if (u < pa) {
      *beta = Float3{0, 0, 0};
      return TrackEvent::kAbsorb;
    }
    if (u < pa + ps) {
      const float k = sum / (mp.sigma_bar * ps);
      *beta = Float3{bs[0] * k, bs[1] * k, bs[2] * k};
      *t_out = t;
      *mp_out = mp;
      return TrackEvent::kScatter;
    }
    const float k = sum / (mp.sigma_bar * pn);
    *beta = Float3{bn[0] * k, bn[1] * k, bn[2] * k};
  }
}

}  // namespace penumbra
