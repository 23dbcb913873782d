#include "penumbra/render/media_realtime.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "penumbra/render/media_common.h"

namespace penumbra {
namespace {

constexpr float kInfF = std::numeric_limits<float>::infinity();

// trilinear lookup in a cell-centred (r0 x r1 x r2) array at continuous index f (cell centre
// i at f = i), clamped to the outermost centres.
template <typename T>
T Trilinear(const T* a, const int r[3], const Eigen::Vector3f& f) {
  int i0[3], i1[3];
  float w[3];
  for (int k = 0; k < 3; ++k) {
    const float c = std::clamp(f[k], 0.0f, static_cast<float>(r[k] - 1));
    i0[k] = std::min(static_cast<int>(c), std::max(r[k] - 2, 0));
    i1[k] = std::min(i0[k] + 1, r[k] - 1);
    w[k] = c - static_cast<float>(i0[k]);
  }
  auto at = [&](int i, int j, int k) { return a[(static_cast<size_t>(k) * r[1] + j) * r[0] + i]; };
  const T c00 = at(i0[0], i0[1], i0[2]) * (1 - w[0]) + at(i1[0], i0[1], i0[2]) * w[0];
  const T c10 = at(i0[0], i1[1], i0[2]) * (1 - w[0]) + at(i1[0], i1[1], i0[2]) * w[0];
  const T c01 = at(i0[0], i0[1], i1[2]) * (1 - w[0]) + at(i1[0], i0[1], i1[2]) * w[0];
  const T c11 = at(i0[0], i1[1], i1[2]) * (1 - w[0]) + at(i1[0], i1[1], i1[2]) * w[0];
  const T c0 = c00 * (1 - w[1]) + c10 * w[1];
  const T c1 = c01 * (1 - w[1]) + c11 * w[1];
  return c0 * (1 - w[2]) + c1 * w[2];
}

Eigen::Vector3f Exp(const Eigen::Vector3f& x) { return x.array().exp().matrix(); }

bool Inside(const AnalyticMedium& m, const Eigen::Vector3f& p) {
  return !m.bounded ||
         ((p.array() >= m.box_min.array()).all() && (p.array() <= m.box_max.array()).all());
}

}  // namespace

void RealtimeMedia::Build(const MediaScene& media, const LightSampler& lights,
                          const RayScene& scene, const Eigen::Vector3f& bounds_center_W,
                          double bounds_extent_m, const Eigen::Vector3f& sky_ambient,
                          ThreadPool* pool) {
  media_ = &media;
  sky_ambient_ = sky_ambient;
  num_lights_ = std::min(lights.size(), kMaxVolumeLights);
  const int nl = num_lights_;
  auto parallel = [&](int64_t n, const std::function<void(int64_t)>& fn) {
    if (pool != nullptr) {
      pool->ParallelFor(n, fn);
    } else {
      for (int64_t i = 0; i < n; ++i) fn(i);
    }
  };

  // grid light volumes.
  grid_light_.assign(media.grids().size(), GridLight());
  for (size_t g = 0; g < media.grids().size(); ++g) {
    const GridVolume& v = media.grids()[g];
    GridLight& gl = grid_light_[g];
    const int n[3] = {v.nx, v.ny, v.nz};
    for (int k = 0; k < 3; ++k) {
      gl.r[k] = std::min(n[k], kGridLightRes);
      gl.cells_per_m[k] = gl.r[k] / (2 * v.half[k]);
    }
    gl.cell_m = (1.0f / gl.cells_per_m.array()).minCoeff();
    const int cells = gl.r[0] * gl.r[1] * gl.r[2];
    gl.T.assign(static_cast<size_t>(nl) * cells, 1.0f);
    gl.source.assign(cells, sky_ambient);
    const Eigen::Matrix3f R_WG = v.R_GW.transpose();
    const float sigma = Mean3(v.sigma_t);
    parallel(cells, [&](int64_t c) {
      const int i = static_cast<int>(c % gl.r[0]);
      const int j = static_cast<int>((c / gl.r[0]) % gl.r[1]);
      const int k = static_cast<int>(c / (static_cast<int64_t>(gl.r[0]) * gl.r[1]));
      const Eigen::Vector3f x_G =
          -v.half + Eigen::Vector3f(i + 0.5f, j + 0.5f, k + 0.5f).cwiseQuotient(gl.cells_per_m);
      const Eigen::Vector3f p = R_WG * (x_G - v.p_GW);
      Eigen::Vector3f src = sky_ambient;
      for (int l = 0; l < nl; ++l) {
        LightSample ls;
        if (!lights.Sample(l, p, 0.5f, 0.5f, &ls)) {
          gl.T[static_cast<size_t>(l) * cells + c] = 0.0f;
          continue;
        }
        float a, b, Tg = 1.0f;
        if (v.Interval(p, ls.wi, 0.0f, ls.distance, &a, &b)) {
          const int steps = std::max(1, static_cast<int>(std::ceil((b - a) / gl.cell_m)));
          const float ds = (b - a) / steps;
          const Eigen::Vector3f o_G = v.ToGrid(p), d_G = v.R_GW * ls.wi;
          float tau = 0;
          for (int s = 0; s < steps; ++s) tau += v.DensityAt(o_G + (a + (s + 0.5f) * ds) * d_G);
          Tg = std::exp(-tau * sigma * ds);
        }
        gl.T[static_cast<size_t>(l) * cells + c] = Tg;
        float V = 1.0f;
        if (ls.cast_shadow) {
          Ray sr;
          sr.o = p;
          sr.d = ls.wi;
          sr.tmax = std::isinf(ls.distance) ? kInfF : ls.distance * (1.0f - 1e-4f);
          if (scene.Occluded(sr)) V = 0.0f;
        }
        if (!(V > 0)) continue;
        const float Th =
            media.analytic().empty()
                ? 1.0f
                : std::exp(-Mean3(media.AnalyticOpticalDepth(p, ls.wi, 0, ls.distance)));
        src += ls.E * (V * Tg * Th * kInv4Pi);
      }
      gl.source[c] = src;
    });
  }

  // visibility volume of the homogeneous media.
  fog_ = FogVolume();
  if (!media.analytic().empty() && nl > 0) {
    Eigen::Vector3f lo = bounds_center_W - Eigen::Vector3f::Constant(bounds_extent_m);
    Eigen::Vector3f hi = bounds_center_W + Eigen::Vector3f::Constant(bounds_extent_m);
    bool all_bounded = true;
    Eigen::Vector3f ulo = Eigen::Vector3f::Constant(kInfF), uhi = Eigen::Vector3f::Constant(-kInfF);
    for (const AnalyticMedium& m : media.analytic()) {
      if (!m.bounded) {
        all_bounded = false;
        break;
      }
      ulo = ulo.cwiseMin(m.box_min);
      uhi = uhi.cwiseMax(m.box_max);
    }
    if (all_bounded) {
      lo = lo.cwiseMax(ulo);
      hi = hi.cwiseMin(uhi);
    }
    const Eigen::Vector3f size = hi - lo;
    if ((size.array() > 0).all()) {
      fog_.active = true;
      fog_.lo = lo;
      fog_.hi = hi;
      const float cell = std::cbrt(size.prod() / kFogCells);
      for (int k = 0; k < 3; ++k) {
        fog_.r[k] = std::clamp(static_cast<int>(std::ceil(size[k] / cell)), 1, 128);
        fog_.cells_per_m[k] = fog_.r[k] / size[k];
      }
      const int cells = fog_.r[0] * fog_.r[1] * fog_.r[2];
      fog_.vis.assign(static_cast<size_t>(nl) * cells, 1.0f);
      parallel(cells, [&](int64_t c) {
        const int i = static_cast<int>(c % fog_.r[0]);
        const int j = static_cast<int>((c / fog_.r[0]) % fog_.r[1]);
        const int k = static_cast<int>(c / (static_cast<int64_t>(fog_.r[0]) * fog_.r[1]));
        const Eigen::Vector3f p =
            lo + Eigen::Vector3f(i + 0.5f, j + 0.5f, k + 0.5f).cwiseQuotient(fog_.cells_per_m);
        for (int l = 0; l < nl; ++l) {
          float& out = fog_.vis[static_cast<size_t>(l) * cells + c];
          LightSample ls;
          if (!lights.Sample(l, p, 0.5f, 0.5f, &ls)) {
            out = 0.0f;
            continue;
          }
          if (ls.cast_shadow) {
            Ray sr;
            sr.o = p;
            sr.d = ls.wi;
            sr.tmax = std::isinf(ls.distance) ? kInfF : ls.distance * (1.0f - 1e-4f);
            if (scene.Occluded(sr)) {
              out = 0.0f;
              continue;
            }
          }
          float T = std::exp(-Mean3(media.AnalyticOpticalDepth(p, ls.wi, 0, ls.distance)));
          for (size_t g = 0; g < grid_light_.size(); ++g)
            T *= GridLightT(static_cast<int>(g), l, p, ls.wi, ls.distance);
          out = T;
        }
      });
    }
  }
}

float RealtimeMedia::GridLightT(int g, int j, const Eigen::Vector3f& p_W, const Eigen::Vector3f& wi,
                                float dist) const {
  if (j >= num_lights_) return 1.0f;
  const GridVolume& v = media_->grids()[g];
  float a, b;
  if (!v.Interval(p_W, wi, 0.0f, dist, &a, &b)) return 1.0f;
  const GridLight& gl = grid_light_[g];
  const Eigen::Vector3f f = (v.ToGrid(p_W + a * wi) + v.half).cwiseProduct(gl.cells_per_m) -
                            Eigen::Vector3f::Constant(0.5f);
  const size_t cells = static_cast<size_t>(gl.r[0]) * gl.r[1] * gl.r[2];
  return Trilinear(gl.T.data() + j * cells, gl.r, f);
}

float RealtimeMedia::FogVisibility(int j, const Eigen::Vector3f& p_W, const Eigen::Vector3f& wi,
                                   float dist) const {
  if (fog_.active && j < num_lights_ && (p_W.array() >= fog_.lo.array()).all() &&
      (p_W.array() <= fog_.hi.array()).all()) {
    const Eigen::Vector3f f =
        (p_W - fog_.lo).cwiseProduct(fog_.cells_per_m) - Eigen::Vector3f::Constant(0.5f);
    const size_t cells = static_cast<size_t>(fog_.r[0]) * fog_.r[1] * fog_.r[2];
    return Trilinear(fog_.vis.data() + j * cells, fog_.r, f);
  }
  float T = std::exp(-Mean3(media_->AnalyticOpticalDepth(p_W, wi, 0, dist)));
  for (size_t g = 0; g < grid_light_.size(); ++g)
    T *= GridLightT(static_cast<int>(g), j, p_W, wi, dist);
  return T;
}

Eigen::Vector3f RealtimeMedia::LightTransmittance(int j, const Eigen::Vector3f& p_W,
                                                  const Eigen::Vector3f& wi, float dist) const {
  Eigen::Vector3f T = media_->analytic().empty()
                          ? Eigen::Vector3f::Ones()
                          : Exp(-media_->AnalyticOpticalDepth(p_W, wi, 0, dist));
  for (size_t g = 0; g < grid_light_.size(); ++g)
    T *= GridLightT(static_cast<int>(g), j, p_W, wi, dist);
  return T;
}

MediaSegment RealtimeMedia::IntegrateView(const LightSampler& lights, const Eigen::Vector3f& o,
                                          const Eigen::Vector3f& d, float t_end, Rng* rng) const {
  MediaSegment out;
  const MediaScene& media = *media_;
  const bool analytic = !media.analytic().empty();

  // grids: march the overlap with each box.
  constexpr int kMaxSegs = 8;
  float seg_a[kMaxSegs], seg_b[kMaxSegs];
  Eigen::Vector3f seg_T[kMaxSegs];
  int nseg = 0;
  Eigen::Vector3f Tg = Eigen::Vector3f::Ones();
  float first_a = kInfF;
  for (size_t g = 0; g < media.grids().size(); ++g) {
    const GridVolume& v = media.grids()[g];
    float a, b;
    if (!v.Interval(o, d, 0.0f, t_end, &a, &b)) continue;
    const GridLight& gl = grid_light_[g];
    const int n = std::clamp(static_cast<int>(std::ceil((b - a) / gl.cell_m)), 1, kMaxGridSteps);
    const float ds = (b - a) / n;
    const float jitter = rng->Uniform();
    const Eigen::Vector3f o_G = v.ToGrid(o), d_G = v.R_GW * d;
    Eigen::Vector3f Tacc = Eigen::Vector3f::Ones(), Lg = Eigen::Vector3f::Zero();
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector3f x = o_G + (a + (i + jitter) * ds) * d_G;
      const float dens = v.DensityAt(x);
      const Eigen::Vector3f em = v.emission ? v.EmissionAt(x) : Eigen::Vector3f::Zero();
      if (!(dens > 0) && !(em.maxCoeff() > 0)) continue;
      const Eigen::Vector3f sig_t = dens * v.sigma_t;
      const Eigen::Vector3f step_T = Exp(-sig_t * ds);
      Eigen::Vector3f factor;
      for (int c = 0; c < 3; ++c)
        factor[c] = sig_t[c] * ds > 1e-5f ? (1.0f - step_T[c]) / sig_t[c] : ds;
      const Eigen::Vector3f f =
          (x + v.half).cwiseProduct(gl.cells_per_m) - Eigen::Vector3f::Constant(0.5f);
      const Eigen::Vector3f src =
          (dens * v.sigma_s).cwiseProduct(Trilinear(gl.source.data(), gl.r, f)) + em;
      Lg += Tacc.cwiseProduct(src).cwiseProduct(factor);
      Tacc = Tacc.cwiseProduct(step_T);
    }
    const Eigen::Vector3f Th_mid = analytic
                                       ? Exp(-media.AnalyticOpticalDepth(o, d, 0, 0.5f * (a + b)))
                                       : Eigen::Vector3f::Ones();
    out.L_add += Tg.cwiseProduct(Th_mid).cwiseProduct(Lg);
    Tg = Tg.cwiseProduct(Tacc);
    first_a = std::min(first_a, a);
    if (nseg < kMaxSegs) {
      seg_a[nseg] = a, seg_b[nseg] = b, seg_T[nseg] = Tacc;
      ++nseg;
    }
  }
  // grid transmittance from the camera to distance t (linear inside a box).
  auto grid_T = [&](float t) {
    Eigen::Vector3f T = Eigen::Vector3f::Ones();
    for (int s = 0; s < nseg; ++s) {
      if (t <= seg_a[s]) continue;
      if (t >= seg_b[s]) {
        T = T.cwiseProduct(seg_T[s]);
      } else {
        const float w = (t - seg_a[s]) / (seg_b[s] - seg_a[s]);
        T = T.cwiseProduct(Eigen::Vector3f::Ones() * (1 - w) + seg_T[s] * w);
      }
    }
    return T;
  };

  if (!analytic) {
    out.T = Tg;
    return out;
  }

  // homogeneous media: closed-form transmittance and sky in-scatter.
  const int nm = static_cast<int>(media.analytic().size());
  constexpr int kMaxMedia = 16;
  double I[kMaxMedia];  // density integral of each medium over the ray
  float ma[kMaxMedia], mb[kMaxMedia];
  Eigen::Vector3d tau_t = Eigen::Vector3d::Zero(), tau_s = Eigen::Vector3d::Zero();
  for (int i = 0; i < nm && i < kMaxMedia; ++i) {
    const AnalyticMedium& m = media.analytic()[i];
    I[i] = 0;
    if (!m.Interval(o, d, 0.0f, t_end, &ma[i], &mb[i])) continue;
    I[i] = std::min(m.DensityIntegral(o.z(), d.z(), ma[i], mb[i]), 1e30);
    tau_t += m.sigma_t.cast<double>() * I[i];
    tau_s += m.sigma_s.cast<double>() * I[i];
  }
  const Eigen::Vector3f Th_end = (-tau_t).array().exp().matrix().cast<float>();
  Eigen::Vector3f albedo;
  for (int c = 0; c < 3; ++c)
    albedo[c] = tau_t[c] > 0 ? static_cast<float>(tau_s[c] / tau_t[c]) : 0;
  Eigen::Vector3f sky_w = Eigen::Vector3f::Ones() - Th_end;
  if (nseg > 0) {
    const Eigen::Vector3f Th_a = Exp(-media.AnalyticOpticalDepth(o, d, 0, first_a));
    sky_w = (Eigen::Vector3f::Ones() - Th_a) + (Th_a - Th_end).cwiseProduct(Tg);
  }
  out.L_add += albedo.cwiseProduct(sky_w).cwiseProduct(sky_ambient_);
  out.T = Th_end.cwiseProduct(Tg);

  // light in-scatter: distances drawn from a mixture over the media, each medium's lobe
  // proportional to its mean-channel sigma_t T along its own overlap.
  if (lights.size() == 0) return out;
  double P[kMaxMedia], P_sum = 0;
  for (int i = 0; i < nm && i < kMaxMedia; ++i) {
    const double sm = Mean3(media.analytic()[i].sigma_t);
    P[i] = I[i] > 0 ? -std::expm1(-sm * I[i]) : 0.0;
    P_sum += P[i];
  }
  if (!(P_sum > 0)) return out;
  const Eigen::Vector3f wo = -d;
  for (int k = 0; k < kFogLightSamples; ++k) {
    const double u = (k + rng->UniformD()) / kFogLightSamples;
    // pick a medium with probability P_i / P_sum, then a distance within it.
    double acc = 0, u_pick = rng->UniformD() * P_sum;
    int pick = 0;
    for (int i = 0; i < nm && i < kMaxMedia; ++i) {
      acc += P[i];
      pick = i;
      if (u_pick < acc && P[i] > 0) break;
    }
    const AnalyticMedium& mp = media.analytic()[pick];
    const double smp = Mean3(mp.sigma_t);
    const double tau_target = -std::log1p(-u * P[pick]) / smp;
    const double t = mp.InvertDensityIntegral(o.z(), d.z(), ma[pick], mb[pick], tau_target);
    if (!std::isfinite(t)) continue;
    const Eigen::Vector3f x = o + static_cast<float>(t) * d;
    // mixture pdf at t.
    double pdf = 0;
    for (int i = 0; i < nm && i < kMaxMedia; ++i) {
      if (!(P[i] > 0) || t < ma[i] || t > mb[i]) continue;
      const AnalyticMedium& m = media.analytic()[i];
      const double sm = Mean3(m.sigma_t);
      const double Ii = m.DensityIntegral(o.z(), d.z(), ma[i], t);
      pdf += (P[i] / P_sum) * sm * m.Density(x.z()) * std::exp(-sm * Ii) / P[i];
    }
    if (!(pdf > 0)) continue;
    Eigen::Vector3f Ls = Eigen::Vector3f::Zero();
    for (int j = 0; j < lights.size(); ++j) {
      LightSample ls;
      const float u1 = rng->Uniform(), u2 = rng->Uniform();
      if (!lights.Sample(j, x, u1, u2, &ls)) continue;
      const float vis = FogVisibility(j, x, ls.wi, ls.distance);
      if (!(vis > 0)) continue;
      const float cos_t = wo.dot(ls.wi);
      Eigen::Vector3f ph = Eigen::Vector3f::Zero();
      for (int i = 0; i < nm && i < kMaxMedia; ++i) {
        const AnalyticMedium& m = media.analytic()[i];
        if (!Inside(m, x)) continue;
        ph += m.sigma_s * (m.Density(x.z()) * HenyeyGreenstein(cos_t, m.g));
      }
      Ls += ls.E.cwiseProduct(ph) * vis;
    }
    const Eigen::Vector3f T_cam = Exp(-media.AnalyticOpticalDepth(o, d, 0, static_cast<float>(t)))
                                      .cwiseProduct(grid_T(static_cast<float>(t)));
    out.L_add += T_cam.cwiseProduct(Ls) * static_cast<float>(1.0 / (pdf * kFogLightSamples));
  }
  return out;
}

}  // namespace penumbra
