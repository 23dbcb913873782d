// the pathtraced tier's shared media formulas (render/media/media_scene_math.h, which MediaScene's
// members and the CUDA path kernels call) against the Eigen code MediaScene ran before the move
// (restated below as `legacy`), bit for bit: the coefficients and phase mixture at a point,
// the phase function and its sampling, ratio-tracked transmittance and spectral delta tracking
// (with the random draws each takes: the next draw after a call is compared too), on
// homogeneous media (uniform, height fog under a layer top, a boxed region, three g values),
// grids (a turned smoke ramp and an emissive fire grid) and both together.

#include "penumbra/render/media/media_scene_math.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <vector>

#include "penumbra/core/rng.h"
#include "penumbra/render/media/media_scene.h"
#include "render/media_test_util.h"

namespace penumbra::testing {
namespace {

bool Same(float a, float b) { return std::memcmp(&a, &b, sizeof(float)) == 0; }
bool Same3(const Eigen::Vector3f& a, const Float3& b) {
  return Same(a.x(), b.x) && Same(a.y(), b.y) && Same(a.z(), b.z);
}

// MediaScene's code before the move to render/media/media_scene_math.h (its Eigen form).
namespace legacy {

constexpr float kInfF = std::numeric_limits<float>::infinity();
constexpr float kInv4PiL = 0.0795774715459476679f;

float Hg(float cos_theta, float g) {
  const float denom = 1.0f + g * g + 2.0f * g * cos_theta;
  return kInv4PiL * (1.0f - g * g) / (denom * std::sqrt(std::max(denom, 1e-12f)));
}

Eigen::Vector3f SampleHg(const Eigen::Vector3f& wo, float g, float u1, float u2, float* pdf) {
  float cos_t;
  if (std::abs(g) < 1e-3f) {
    cos_t = 1.0f - 2.0f * u1;
  } else {
    const float s = (1.0f - g * g) / (1.0f + g - 2.0f * g * u1);
    cos_t = (1.0f + g * g - s * s) / (2.0f * g);
  }
  cos_t = std::clamp(cos_t, -1.0f, 1.0f);
  const float sin_t = std::sqrt(std::max(0.0f, 1.0f - cos_t * cos_t));
  float sp, cp;
  SinCos2Pi(u2, &sp, &cp);
  const Eigen::Vector3f w = -wo;
  const float sign = w.z() >= 0 ? 1.0f : -1.0f;
  const float a = -1.0f / (sign + w.z());
  const float b = w.x() * w.y() * a;
  const Eigen::Vector3f t(1.0f + sign * w.x() * w.x() * a, sign * b, -sign * w.x());
  const Eigen::Vector3f bt(b, sign + w.y() * w.y() * a, -w.y());
  const Eigen::Vector3f wi = (sin_t * cp * t + sin_t * sp * bt + cos_t * w).normalized();
  *pdf = Hg(wo.dot(wi), g);
  return wi;
}

struct Point {
  Eigen::Vector3f sigma_t{0, 0, 0}, sigma_s{0, 0, 0}, emission{0, 0, 0};
  float sigma_bar = 0;
  int lobes = 0;
  std::array<float, 8> weight{}, g{};
  float Phase(float c) const {
    float sum = 0, wsum = 0;
    for (int i = 0; i < lobes; ++i) {
      sum += weight[i] * Hg(c, g[i]);
      wsum += weight[i];
    }
    return wsum > 0 ? sum / wsum : kInv4PiL;
  }
  Eigen::Vector3f SamplePhase(const Eigen::Vector3f& wo, float u0, float u1, float u2,
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
    const Eigen::Vector3f wi = SampleHg(wo, lobes > 0 ? g[pick] : 0.0f, u1, u2, &lobe_pdf);
    *pdf = lobes > 1 ? Phase(wo.dot(wi)) : lobe_pdf;
    return wi;
  }
};

bool Cell(const GridVolume& v, const Eigen::Vector3f& x_G, int i0[3], int i1[3], float w[3]) {
  if (std::abs(x_G.x()) > v.half.x() || std::abs(x_G.y()) > v.half.y() ||
      std::abs(x_G.z()) > v.half.z())
    return false;
  const Eigen::Vector3f f =
      (x_G + v.half).cwiseProduct(v.voxels_per_m) - Eigen::Vector3f::Constant(0.5f);
  const int n[3] = {v.nx, v.ny, v.nz};
  for (int k = 0; k < 3; ++k) {
    const float c = std::clamp(f[k], 0.0f, static_cast<float>(n[k] - 1));
    i0[k] = std::min(static_cast<int>(c), std::max(n[k] - 2, 0));
    i1[k] = std::min(i0[k] + 1, n[k] - 1);
    w[k] = c - static_cast<float>(i0[k]);
  }
  return true;
}

float Density(const GridVolume& v, const Eigen::Vector3f& x_G) {
  int i0[3], i1[3];
  float w[3];
  if (!Cell(v, x_G, i0, i1, w)) return 0.0f;
  const float* D = v.density->data();
  auto at = [&](int i, int j, int k) { return D[(static_cast<size_t>(k) * v.ny + j) * v.nx + i]; };
  const float c00 = at(i0[0], i0[1], i0[2]) * (1 - w[0]) + at(i1[0], i0[1], i0[2]) * w[0];
  const float c10 = at(i0[0], i1[1], i0[2]) * (1 - w[0]) + at(i1[0], i1[1], i0[2]) * w[0];
  const float c01 = at(i0[0], i0[1], i1[2]) * (1 - w[0]) + at(i1[0], i0[1], i1[2]) * w[0];
  const float c11 = at(i0[0], i1[1], i1[2]) * (1 - w[0]) + at(i1[0], i1[1], i1[2]) * w[0];
  const float c0 = c00 * (1 - w[1]) + c10 * w[1];
  const float c1 = c01 * (1 - w[1]) + c11 * w[1];
  return c0 * (1 - w[2]) + c1 * w[2];
}

Eigen::Vector3f Emission(const GridVolume& v, const Eigen::Vector3f& x_G) {
  if (!v.emission) return Eigen::Vector3f::Zero();
  int i0[3], i1[3];
  float w[3];
  if (!Cell(v, x_G, i0, i1, w)) return Eigen::Vector3f::Zero();
  const float* E = v.emission->data();
  Eigen::Vector3f sum = Eigen::Vector3f::Zero();
  for (int c = 0; c < 8; ++c) {
    const int i = c & 1 ? i1[0] : i0[0], j = c & 2 ? i1[1] : i0[1], k = c & 4 ? i1[2] : i0[2];
    const float wt =
        (c & 1 ? w[0] : 1 - w[0]) * (c & 2 ? w[1] : 1 - w[1]) * (c & 4 ? w[2] : 1 - w[2]);
    const float* e = E + ((static_cast<size_t>(k) * v.ny + j) * v.nx + i) * 3;
    sum += wt * Eigen::Vector3f(e[0], e[1], e[2]);
  }
  return sum;
}

bool GridInterval(const GridVolume& v, const Eigen::Vector3f& o, const Eigen::Vector3f& d, float t0,
                  float t1, float* a, float* b) {
  const Eigen::Vector3f o_G = v.ToGrid(o), d_G = v.R_GW * d, lo = -v.half;
  return MediaSlabInterval(o_G.data(), d_G.data(), lo.data(), v.half.data(), t0, t1, a, b);
}

float Mean(const Eigen::Vector3f& v) { return (v.x() + v.y() + v.z()) * (1.0f / 3.0f); }

Point At(const MediaScene& s, const Eigen::Vector3f& p) {
  Point mp;
  auto add_lobe = [&](float w, float g) {
    if (!(w > 0)) return;
    for (int i = 0; i < mp.lobes; ++i)
      if (mp.g[i] == g) {
        mp.weight[i] += w;
        return;
      }
    if (mp.lobes < 8) {
      mp.weight[mp.lobes] = w;
      mp.g[mp.lobes] = g;
      ++mp.lobes;
    } else {
      mp.weight[mp.lobes - 1] += w;
    }
  };
  for (const AnalyticMedium& m : s.analytic()) {
    if (m.bounded &&
        ((p.array() < m.box_min.array()).any() || (p.array() > m.box_max.array()).any()))
      continue;
    const float h =
        m.falloff > 0 && p.z() > m.base ? std::exp(-m.falloff * (p.z() - m.base)) : 1.0f;
    mp.sigma_t += h * m.sigma_t;
    mp.sigma_s += h * m.sigma_s;
    mp.sigma_bar += h * m.sigma_bar;
    add_lobe(h * Mean(m.sigma_s), m.g);
  }
  for (const GridVolume& v : s.grids()) {
    const Eigen::Vector3f x = v.ToGrid(p);
    if (std::abs(x.x()) > v.half.x() || std::abs(x.y()) > v.half.y() ||
        std::abs(x.z()) > v.half.z())
      continue;
    const float dens = Density(v, x);
    mp.sigma_t += dens * v.sigma_t;
    mp.sigma_s += dens * v.sigma_s;
    mp.sigma_bar += v.majorant;
    if (v.emission) mp.emission += Emission(v, x);
    add_lobe(dens * Mean(v.sigma_s), v.g);
  }
  return mp;
}

Eigen::Vector3f Transmittance(const MediaScene& s, const Eigen::Vector3f& o,
                              const Eigen::Vector3f& d, float t0, float t1, Rng* rng) {
  Eigen::Vector3f T = (-s.AnalyticOpticalDepth(o, d, t0, t1)).array().exp().matrix();
  for (const GridVolume& v : s.grids()) {
    if (!(T.maxCoeff() > 0)) return Eigen::Vector3f::Zero();
    float a, b;
    if (!GridInterval(v, o, d, t0, t1, &a, &b)) continue;
    const float inv_maj = 1.0f / v.majorant;
    const Eigen::Vector3f d_G = v.R_GW * d, o_G = v.ToGrid(o);
    float t = a;
    for (;;) {
      t -= std::log(1.0f - rng->Uniform()) * inv_maj;
      if (t >= b) break;
      const float dens = Density(v, o_G + t * d_G);
      T = T.cwiseProduct((Eigen::Vector3f::Ones() - dens * inv_maj * v.sigma_t).cwiseMax(0.0f));
      const float m = T.maxCoeff();
      if (m < 0.05f) {
        if (!(m > 0) || rng->Uniform() >= 0.5f) return Eigen::Vector3f::Zero();
        T *= 2.0f;
      }
    }
  }
  return T;
}

TrackEvent Track(const MediaScene& s, const Eigen::Vector3f& o, const Eigen::Vector3f& d, float t0,
                 float t1, Rng* rng, Eigen::Vector3f* beta, Eigen::Vector3f* L, float* t_out,
                 Point* mp_out) {
  float t = t0;
  for (;;) {
    float t_next = kInfF;
    for (const AnalyticMedium& m : s.analytic()) {
      float a, b;
      if (!m.Interval(o, d, t, std::min(t1, t_next), &a, &b)) continue;
      const double tau = -std::log(1.0 - rng->UniformD()) / m.sigma_bar;
      const double tt = m.InvertDensityIntegral(o.z(), d.z(), a, b, tau);
      if (tt < t_next) t_next = static_cast<float>(tt);
    }
    for (const GridVolume& v : s.grids()) {
      float a, b;
      if (!GridInterval(v, o, d, t, std::min(t1, t_next), &a, &b)) continue;
      const float tt = a - std::log(1.0f - rng->Uniform()) / v.majorant;
      if (tt < b && tt < t_next) t_next = tt;
    }
    if (!(t_next < t1)) return TrackEvent::kNone;
    t = std::max(t_next, std::nextafter(t, kInfF));
    const Point mp = At(s, o + t * d);
    if (!(mp.sigma_bar > 0)) continue;
    if (mp.emission.maxCoeff() > 0) *L += beta->cwiseProduct(mp.emission) / mp.sigma_bar;
    const Eigen::Vector3f sigma_a = (mp.sigma_t - mp.sigma_s).cwiseMax(0.0f);
    const Eigen::Vector3f sigma_n =
        (Eigen::Vector3f::Constant(mp.sigma_bar) - mp.sigma_t).cwiseMax(0.0f);
    const float pa = Mean(beta->cwiseProduct(sigma_a));
    const float ps = Mean(beta->cwiseProduct(mp.sigma_s));
    const float pn = Mean(beta->cwiseProduct(sigma_n));
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

}  // namespace legacy

bool SamePoint(const legacy::Point& a, const MediumPointPod& b) {
  if (!Same3(a.sigma_t, b.sigma_t) || !Same3(a.sigma_s, b.sigma_s) ||
      !Same3(a.emission, b.emission) || !Same(a.sigma_bar, b.sigma_bar) || a.lobes != b.lobes)
    return false;
  for (int i = 0; i < a.lobes; ++i)
    if (!Same(a.weight[i], b.weight[i]) || !Same(a.g[i], b.g[i])) return false;
  return true;
}

// three homogeneous media (uniform haze, height fog under a layer top, a boxed dust region),
// three g values.
void AddHomogeneous(EffectsFrame* fx) {
  HomogeneousMedium haze = Fog(0.08f, 0.95f, 0.0f);
  haze.sigma_t_per_m = Eigen::Vector3f(0.07f, 0.08f, 0.1f);
  fx->homogeneous_media.push_back(haze);
  HomogeneousMedium low = Fog(0.4f, 0.9f, 0.3f);
  low.height_falloff_per_m = 0.6f;
  low.base_height_m = 0.4f;
  low.layer_top_m = 2.5f;
  fx->homogeneous_media.push_back(low);
  HomogeneousMedium dust = Fog(1.1f, 0.6f, 0.7f);
  dust.sigma_t_per_m = Eigen::Vector3f(1.3f, 1.1f, 0.9f);
  dust.region = BoxRegion{Eigen::Vector3d(-1, -1.5, 0), Eigen::Vector3d(1.5, 1, 1.8)};
  fx->homogeneous_media.push_back(dust);
}

// a turned smoke ramp and an emissive fire grid.
void AddGrids(EffectsFrame* fx) {
  GridMedium smoke = RampGrid({0.5, 0.3, 1.2}, {1.2, 0.9, 1.0}, 20, 1.0f, 0.4f, 1.2f, 0.8f);
  smoke.X_WG.linear() = (Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()) *
                         Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY()))
                            .toRotationMatrix();
  smoke.g = 0.2f;
  fx->grid_media.push_back(smoke);
  GridMedium fire = RampGrid({-0.5, -1.0, 0.6}, {0.4, 0.4, 0.6}, 8, 0.6f, 0.2f, 2.0f, 0.3f);
  auto e = std::make_shared<std::vector<float>>(static_cast<size_t>(8) * 2 * 2 * 3);
  for (size_t i = 0; i < e->size(); ++i) (*e)[i] = 40.0f + 5.0f * static_cast<float>(i % 7);
  fire.emission = e;
  fx->grid_media.push_back(fire);
}

struct Counts {
  int points_in = 0, lobed = 0, scatters = 0, absorbs = 0, throughs = 0, emitted = 0;
  int partial_T = 0;
};

Counts CheckAgainstLegacy(const EffectsFrame& fx) {
  MediaScene media;
  media.Build(&fx);
  const MediaSceneView view = media.View();
  Counts n;
  Rng pick(17);
  auto random_dir = [&]() {
    const Eigen::Vector3f d(pick.Uniform() - 0.5f, pick.Uniform() - 0.5f, pick.Uniform() - 0.5f);
    return Eigen::Vector3f(d.normalized());
  };
  for (int i = 0; i < 4000; ++i) {
    const Eigen::Vector3f p(-2.5f + 5 * pick.Uniform(), -2.5f + 5 * pick.Uniform(),
                            -0.5f + 3.5f * pick.Uniform());
    // the medium at a point, its phase function and its sampling
    const legacy::Point want = legacy::At(media, p);
    const MediumPointPod got = MediaPointAt(view, p.data());
    EXPECT_TRUE(SamePoint(want, got)) << i;
    EXPECT_TRUE(SamePoint(want, media.At(p))) << i;
    n.points_in += want.sigma_bar > 0 ? 1 : 0;
    n.lobed += want.lobes > 1 ? 1 : 0;
    const Eigen::Vector3f wo = random_dir(), wi = random_dir();
    EXPECT_TRUE(Same(want.Phase(wo.dot(wi)),
                     MediaPhase(got, EigenDot({wo.x(), wo.y(), wo.z()}, {wi.x(), wi.y(), wi.z()}))))
        << i;
    const float u0 = pick.Uniform(), u1 = pick.Uniform(), u2 = pick.Uniform();
    float pdf_want, pdf_got;
    const Eigen::Vector3f s_want = want.SamplePhase(wo, u0, u1, u2, &pdf_want);
    const Float3 s_got = MediaSamplePhase(got, {wo.x(), wo.y(), wo.z()}, u0, u1, u2, &pdf_got);
    EXPECT_TRUE(Same3(s_want, s_got) && Same(pdf_want, pdf_got)) << i;

    // a shadow ray's transmittance and a free flight from p, with their random draws
    const Eigen::Vector3f d = random_dir();
    const float t1 = i % 5 == 0 ? std::numeric_limits<float>::infinity() : 6 * pick.Uniform();
    const uint64_t seed = HashKeys(99, static_cast<uint64_t>(i));
    Rng ra(seed), rb(seed);
    const Eigen::Vector3f T_want = legacy::Transmittance(media, p, d, 0.0f, t1, &ra);
    const Float3 T_got = MediaTransmittanceOf(view, p.data(), d.data(), 0.0f, t1, &rb);
    EXPECT_TRUE(Same3(T_want, T_got)) << i;
    EXPECT_EQ(ra.NextU64(), rb.NextU64()) << i;
    n.partial_T += T_want.maxCoeff() > 0 && T_want.maxCoeff() < 0.99f ? 1 : 0;

    Eigen::Vector3f beta_want(0.4f + pick.Uniform(), 0.4f + pick.Uniform(), 0.4f + pick.Uniform());
    Float3 beta_got{beta_want.x(), beta_want.y(), beta_want.z()};
    Eigen::Vector3f L_want(0.1f, 0.2f, 0.3f);
    Float3 L_got{0.1f, 0.2f, 0.3f};
    float t_want = -1, t_got = -1;
    legacy::Point mp_want;
    MediumPointPod mp_got;
    Rng ta(seed + 1), tb(seed + 1);
    const TrackEvent ev_want =
        legacy::Track(media, p, d, 0.0f, t1, &ta, &beta_want, &L_want, &t_want, &mp_want);
    const TrackEvent ev_got =
        MediaTrackOf(view, p.data(), d.data(), 0.0f, t1, &tb, &beta_got, &L_got, &t_got, &mp_got);
    EXPECT_EQ(ev_want, ev_got) << i;
    EXPECT_TRUE(Same3(beta_want, beta_got) && Same3(L_want, L_got)) << i;
    EXPECT_EQ(ta.NextU64(), tb.NextU64()) << i;
    if (ev_want == TrackEvent::kScatter && ev_got == TrackEvent::kScatter) {
      EXPECT_TRUE(Same(t_want, t_got) && SamePoint(mp_want, mp_got)) << i;
      ++n.scatters;
    }
    n.absorbs += ev_want == TrackEvent::kAbsorb ? 1 : 0;
    n.throughs += ev_want == TrackEvent::kNone ? 1 : 0;
    n.emitted += L_want.x() != 0.1f ? 1 : 0;
  }
  return n;
}

TEST(MediaSceneMathTest, HomogeneousMediaAreTheEigenCodesBitForBit) {
  EffectsFrame fx;
  AddHomogeneous(&fx);
  const Counts n = CheckAgainstLegacy(fx);
  EXPECT_GT(n.points_in, 3000);
  EXPECT_GT(n.lobed, 500);  // points in two or three media: a mixture of lobes
  EXPECT_GT(n.scatters, 500);
  EXPECT_GT(n.absorbs, 100);
  EXPECT_GT(n.throughs, 500);
  EXPECT_GT(n.partial_T, 1000);
}

TEST(MediaSceneMathTest, GridsAreTheEigenCodesBitForBit) {
  EffectsFrame fx;
  AddGrids(&fx);
  const Counts n = CheckAgainstLegacy(fx);
  EXPECT_GT(n.points_in, 300);
  EXPECT_GT(n.scatters, 100);
  EXPECT_GT(n.emitted, 50);  // flights through the fire gather its emission
  EXPECT_GT(n.partial_T, 300);
}

TEST(MediaSceneMathTest, HomogeneousMediaAndGridsTogetherAreTheEigenCodesBitForBit) {
  EffectsFrame fx;
  AddHomogeneous(&fx);
  AddGrids(&fx);
  const Counts n = CheckAgainstLegacy(fx);
  EXPECT_GT(n.lobed, 500);
  EXPECT_GT(n.scatters, 500);
  EXPECT_GT(n.emitted, 20);
}

}  // namespace
}  // namespace penumbra::testing
