#include "penumbra/render/film/denoiser.h"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <cstring>

#include "penumbra/core/error.h"
#include "penumbra/core/rng.h"

namespace penumbra {
namespace {

constexpr int kW = 64, kH = 48, kEdge = 32;  // columns < kEdge are region A

// a synthetic frame: two flat regions split at column kEdge, and its guides.
struct Frame {
  ImageF clean{kW, kH, 3}, noisy{kW, kH, 3}, albedo{kW, kH, 3}, normal{kW, kH, 3}, depth{kW, kH, 1},
      variance{kW, kH, 1};
  float noise_std[2] = {0, 0};  // per region, radiance units
};

enum class EdgeKind { kNormal, kDepth };

// region A: albedo 0.5, irradiance 200 -> radiance 100; region B: albedo 0.8, radiance 320.
// A is a plane slanted in depth (depth grows along u), B faces the camera. with kNormal the
// regions meet at the same depth with perpendicular normals; with kDepth they share a normal
// and B lies 1 m behind. noise: zero-mean, std 25% (A) and 15% (B) of the radiance, grey.
Frame MakeFrame(EdgeKind kind, uint64_t seed) {
  Frame f;
  f.noise_std[0] = 25.0f;
  f.noise_std[1] = 48.0f;
  Rng rng(HashKeys(seed, 99));
  for (int v = 0; v < kH; ++v) {
    for (int u = 0; u < kW; ++u) {
      const bool a = u < kEdge;
      const float alb = a ? 0.5f : 0.8f;
      const float rad = a ? 100.0f : 320.0f;
      const float za = 2.0f + 0.01f * u;
      float z =
          a ? za : (kind == EdgeKind::kDepth ? 2.0f + 0.01f * kEdge + 1.0f : 2.0f + 0.01f * kEdge);
      Eigen::Vector3f n(0, 0, -1);
      if (!a && kind == EdgeKind::kNormal) n = {-1, 0, 0};
      // sum of 4 uniforms: mean 2, variance 1/3 -> scaled to unit variance.
      float g = 0;
      for (int k = 0; k < 4; ++k) g += rng.Uniform();
      g = (g - 2.0f) * std::sqrt(3.0f);
      const float sd = f.noise_std[a ? 0 : 1];
      for (int k = 0; k < 3; ++k) {
        f.clean.at(u, v)[k] = rad;
        f.noisy.at(u, v)[k] = rad + sd * g;
        f.albedo.at(u, v)[k] = alb;
        f.normal.at(u, v)[k] = n[k];
      }
      f.depth.at(u, v)[0] = z;
      f.variance.at(u, v)[0] = sd * sd;
    }
  }
  return f;
}

// mean squared error against the clean image over columns [c0, c1), channel 0.
double Mse(const ImageF& img, const ImageF& clean, int c0, int c1) {
  double s = 0;
  int count = 0;
  for (int v = 0; v < kH; ++v)
    for (int u = c0; u < c1; ++u, ++count) {
      const double d = img.at(u, v)[0] - clean.at(u, v)[0];
      s += d * d;
    }
  return s / count;
}

double ColumnMean(const ImageF& img, int u) {
  double s = 0;
  for (int v = 0; v < kH; ++v) s += img.at(u, v)[0];
  return s / kH;
}

void ExpectDenoisedAndEdgePreserved(const Frame& f, const ImageF& out) {
  // variance inside each region (away from the 1 px band at the edge) drops by more than 4x.
  const double in_a = Mse(f.noisy, f.clean, 0, kEdge - 1), out_a = Mse(out, f.clean, 0, kEdge - 1);
  const double in_b = Mse(f.noisy, f.clean, kEdge + 1, kW),
               out_b = Mse(out, f.clean, kEdge + 1, kW);
  EXPECT_LT(out_a * 4, in_a) << "region A variance " << in_a << " -> " << out_a;
  EXPECT_LT(out_b * 4, in_b) << "region B variance " << in_b << " -> " << out_b;
  // no bleeding: every column beyond 1 px from the edge keeps its region's level within 5%
  // of the step (the filtered noise leaves low-frequency residuals of a few units; a pixel
  // that mixed in the other side by 10% would be off by 22).
  const double step = 320.0 - 100.0;
  for (int u = 0; u < kW; ++u) {
    if (u == kEdge - 1 || u == kEdge) continue;
    const double truth = u < kEdge ? 100.0 : 320.0;
    EXPECT_NEAR(ColumnMean(out, u), truth, 0.05 * step) << "column " << u;
  }
}

// the clean step with a variance buffer that claims the noise level: the colour test then
// lets the two sides mix, so only the normal / depth tests keep the edge. every pixel,
// including those at the edge, must keep its value.
void ExpectGeometryStopsTheStep(const Frame& f) {
  ImageF out;
  Denoiser().Denoise(f.clean, {&f.albedo, &f.normal, &f.depth, &f.variance}, nullptr, &out);
  for (int v = 0; v < kH; ++v)
    for (int u = 0; u < kW; ++u)
      ASSERT_NEAR(out.at(u, v)[0], f.clean.at(u, v)[0], 1e-3 * f.clean.at(u, v)[0])
          << u << "," << v;
}

TEST(DenoiserTest, ReducesNoiseAndPreservesNormalEdge) {
  const Frame f = MakeFrame(EdgeKind::kNormal, 1);
  ThreadPool pool(2);
  ImageF out;
  Denoiser().Denoise(f.noisy, {&f.albedo, &f.normal, &f.depth, &f.variance}, &pool, &out);
  ExpectDenoisedAndEdgePreserved(f, out);
  ExpectGeometryStopsTheStep(f);
}

TEST(DenoiserTest, ReducesNoiseAndPreservesDepthEdge) {
  const Frame f = MakeFrame(EdgeKind::kDepth, 2);
  ThreadPool pool(2);
  ImageF out;
  Denoiser().Denoise(f.noisy, {&f.albedo, &f.normal, &f.depth, &f.variance}, &pool, &out);
  ExpectDenoisedAndEdgePreserved(f, out);
  ExpectGeometryStopsTheStep(f);
}

TEST(DenoiserTest, WorksWithSpatialVarianceEstimate) {
  for (EdgeKind kind : {EdgeKind::kNormal, EdgeKind::kDepth}) {
    const Frame f = MakeFrame(kind, 3);
    ImageF out;
    Denoiser().Denoise(f.noisy, {&f.albedo, &f.normal, &f.depth, nullptr}, nullptr, &out);
    ExpectDenoisedAndEdgePreserved(f, out);
  }
}

TEST(DenoiserTest, NoiseFreeImagePassesThrough) {
  // textured albedo, smoothly varying and discontinuous lighting, a background region:
  // with zero variance (a converged render) nothing may change.
  Frame f = MakeFrame(EdgeKind::kNormal, 4);
  Rng rng(HashKeys(4, 5));
  for (int v = 0; v < kH; ++v) {
    for (int u = 0; u < kW; ++u) {
      const bool background = v < 4;
      for (int k = 0; k < 3; ++k) {
        const float alb = 0.05f + 0.9f * rng.Uniform();
        const float irr = 50.0f + 3.0f * u + 10.0f * k + (v > kH / 2 ? 400.0f : 0.0f) +
                          20.0f * std::sin(0.3f * v);
        f.albedo.at(u, v)[k] = background ? 0.0f : alb;
        f.clean.at(u, v)[k] = background ? 1000.0f + u : alb * irr;
      }
      if (background) {
        f.depth.at(u, v)[0] = 0;
        for (int k = 0; k < 3; ++k) f.normal.at(u, v)[k] = 0;
      }
      f.variance.at(u, v)[0] = 0;
    }
  }
  ImageF out;
  Denoiser().Denoise(f.clean, {&f.albedo, &f.normal, &f.depth, &f.variance}, nullptr, &out);
  for (size_t i = 0; i < out.data.size(); ++i)
    ASSERT_NEAR(out.data[i], f.clean.data[i], 1e-4 * std::abs(f.clean.data[i])) << i;

  // without a variance buffer, lighting that is constant per surface still passes through:
  // demodulation removes the texture exactly.
  ImageF flat = f.clean;
  for (int v = 4; v < kH; ++v)
    for (int u = 0; u < kW; ++u)
      for (int k = 0; k < 3; ++k)
        flat.at(u, v)[k] = f.albedo.at(u, v)[k] * (u < kEdge ? 120.0f : 700.0f);
  Denoiser().Denoise(flat, {&f.albedo, &f.normal, &f.depth, nullptr}, nullptr, &out);
  for (size_t i = 0; i < out.data.size(); ++i)
    ASSERT_NEAR(out.data[i], flat.data[i], 1e-4 * std::abs(flat.data[i])) << i;
}

TEST(DenoiserTest, ResultDoesNotDependOnThreadCount) {
  const Frame f = MakeFrame(EdgeKind::kDepth, 6);
  ImageF one, two;
  ThreadPool p1(1), p2(2);
  Denoiser().Denoise(f.noisy, {&f.albedo, &f.normal, &f.depth, &f.variance}, &p1, &one);
  Denoiser().Denoise(f.noisy, {&f.albedo, &f.normal, &f.depth, &f.variance}, &p2, &two);
  ASSERT_EQ(one.data.size(), two.data.size());
  EXPECT_EQ(0, std::memcmp(one.data.data(), two.data.data(), one.data.size() * sizeof(float)));
}

TEST(DenoiserTest, RejectsBadInput) {
  const Frame f = MakeFrame(EdgeKind::kDepth, 7);
  ImageF out;
  ImageF small(kW / 2, kH, 1);
  EXPECT_THROW(Denoiser().Denoise(f.noisy, {&f.albedo, &f.normal, &small, nullptr}, nullptr, &out),
               Error);
  EXPECT_THROW(Denoiser().Denoise(f.noisy, {nullptr, &f.normal, &f.depth, nullptr}, nullptr, &out),
               Error);
  DenoiserSettings bad;
  bad.iterations = 0;
  EXPECT_THROW(Denoiser{bad}, ConfigError);
}

}  // namespace
}  // namespace penumbra
