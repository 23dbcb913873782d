// transmittance through participating media in both render tiers: Beer-Lambert through a
// purely absorbing homogeneous medium, MOR -> extinction, closed-form height fog, ratio and
// delta tracking through a density ramp, realtime vs pathtraced behind that ramp.

#include <gtest/gtest.h>

#include <cmath>

#include "penumbra/core/error.h"
#include "penumbra/render/media/media_common.h"
#include "penumbra/render/media/media_scene.h"
#include "render/media_test_util.h"

namespace penumbra {
namespace {

using namespace penumbra::testing;

constexpr int kW = 48, kH = 36;
constexpr double kFovy = 20;

// mean of rendered / expected (L_e exp(-sigma r), r the range of each pixel's centre ray).
double RenderedOverExpected(RenderSettings::Tier tier, double distance, float sigma_t, int spp) {
  const float Le = 2.0f;
  const SceneDescription s = EmissiveWallScene(distance, Le);
  EffectsFrame fx;
  fx.homogeneous_media.push_back(Fog(sigma_t, 0.0f));
  auto r = MakeRenderer(s, TierSettings(tier, spp));
  const CameraView view = MakeView(CameraLookingAlongX(), kW, kH, kFovy, true, true, false);
  RenderedFrame f;
  r->Render(IdentitySnapshot(s), &fx, view, &f);
  double got = 0, want = 0;
  for (int v = 0; v < kH; ++v)
    for (int u = 0; u < kW; ++u) {
      got += f.radiance.at(u, v)[1];
      want += Le * std::exp(-sigma_t * RangeOfPixel(view.intrinsics, u, v, distance));
    }
  return got / want;
}

TEST(MediaTransmittanceTest, AbsorbingFogRealtimeMatchesBeerLambert) {
  for (double d : {1.0, 3.0, 6.0}) {
    const double ratio = RenderedOverExpected(RenderSettings::Tier::kRealtime, d, 0.25f, 1);
    EXPECT_NEAR(ratio, 1.0, 0.01) << "distance " << d;
    RecordProperty("realtime_ratio_d" + std::to_string(static_cast<int>(d)), std::to_string(ratio));
  }
}

TEST(MediaTransmittanceTest, AbsorbingFogPathtracedMatchesBeerLambert) {
  for (double d : {1.0, 3.0, 6.0}) {
    const double ratio = RenderedOverExpected(RenderSettings::Tier::kPathtraced, d, 0.25f, 256);
    EXPECT_NEAR(ratio, 1.0, 0.01) << "distance " << d;
    RecordProperty("pathtraced_ratio_d" + std::to_string(static_cast<int>(d)),
                   std::to_string(ratio));
  }
}

TEST(MediaTransmittanceTest, MorGivesFivePercentTransmittance) {
  EXPECT_NEAR(SigmaTFromMorM(30.0), std::log(20.0) / 30.0, 1e-15);
  EXPECT_NEAR(std::exp(-SigmaTFromMorM(30.0) * 30.0), 0.05, 1e-12);
  EXPECT_NEAR(MorMFromSigmaT(SigmaTFromMorM(250.0)), 250.0, 1e-9);
  // rendered: the centre pixels of an emissive wall at the MOR show 5 % of its radiance.
  const double mor = 8.0;
  const float Le = 10.0f;
  const SceneDescription s = EmissiveWallScene(mor, Le);
  EffectsFrame fx;
  fx.homogeneous_media.push_back(Fog(static_cast<float>(SigmaTFromMorM(mor)), 0.0f));
  auto r = MakeRenderer(s, TierSettings(RenderSettings::Tier::kRealtime));
  const CameraView view = MakeView(CameraLookingAlongX(), 9, 9, 2, true, false, false);
  RenderedFrame f;
  r->Render(IdentitySnapshot(s), &fx, view, &f);
  EXPECT_NEAR(f.radiance.at(4, 4)[1] / Le, 0.05, 0.05 * 0.01);
}

TEST(MediaTransmittanceTest, HeightFogOpticalDepthMatchesQuadrature) {
  HomogeneousMedium h = Fog(0.3f, 1.0f);
  h.height_falloff_per_m = 0.7f;
  h.base_height_m = 1.0f;
  EffectsFrame fx;
  fx.homogeneous_media.push_back(h);
  MediaScene media;
  media.Build(&fx);
  const AnalyticMedium& m = media.analytic()[0];
  const Eigen::Vector3f o(0, 0, 0.2f);
  for (Eigen::Vector3f d : {Eigen::Vector3f(1, 0, 0.5f), Eigen::Vector3f(1, 0, -0.3f),
                            Eigen::Vector3f(0, 1, 0), Eigen::Vector3f(0.2f, 0, 1)}) {
    d.normalize();
    const Eigen::Vector3f oo = d.z() < 0 ? Eigen::Vector3f(0, 0, 5) : o;
    const double L = 12;
    double quad = 0;
    const int n = 200000;
    for (int i = 0; i < n; ++i) quad += m.Density(oo.z() + d.z() * (i + 0.5) * L / n) * L / n;
    const double closed = m.DensityIntegral(oo.z(), d.z(), 0, L);
    EXPECT_NEAR(closed, quad, 1e-4 * quad) << d.transpose();
    EXPECT_NEAR(media.AnalyticOpticalDepth(oo, d, 0, L).x(), 0.3 * quad, 1e-4 * quad);
    // the inverse returns the distance at which half of the integral is reached.
    const double t_half = m.InvertDensityIntegral(oo.z(), d.z(), 0, L, 0.5 * closed);
    EXPECT_NEAR(m.DensityIntegral(oo.z(), d.z(), 0, t_half), 0.5 * closed, 1e-6 * closed);
  }
  // upwards to infinity the integral converges (the fog thins out), downwards it does not.
  const double up = m.DensityIntegral(0.2, 1.0, 0, std::numeric_limits<double>::infinity());
  EXPECT_NEAR(up, 0.8 + 1.0 / 0.7, 1e-6);
}

TEST(MediaTransmittanceTest, RatioAndDeltaTrackingThroughDensityRamp) {
  const double a = 0.5, b = 0.4, half = 1.0, sigma = 2.0;
  const int nx = 32;
  EffectsFrame fx;
  fx.grid_media.push_back(RampGrid({0, 0, 0}, {half, 0.5, 0.5}, nx, a, b, sigma, 0.0f));
  MediaScene media;
  media.Build(&fx);
  const double tau = sigma * RampIntegral(half, nx, a, b);
  const double expected = std::exp(-tau);
  const Eigen::Vector3f o(-2, 0.1f, -0.2f), d(1, 0, 0);
  // ratio tracking.
  const int n = 20000;
  double sum = 0;
  for (int i = 0; i < n; ++i) {
    Rng rng(HashKeys(11, i));
    sum += media.Transmittance(o, d, 0, 4, &rng).y();
  }
  const double ratio_T = sum / n;
  EXPECT_NEAR(ratio_T, expected, 0.02 * expected);
  RecordProperty("ratio_tracking_rel_err", std::to_string(ratio_T / expected - 1));
  // delta tracking (albedo 0: a path survives iff no real collision).
  const int m = 200000;
  int survived = 0;
  for (int i = 0; i < m; ++i) {
    Rng rng(HashKeys(12, i));
    Eigen::Vector3f beta(1, 1, 1), L(0, 0, 0);
    float t;
    MediumPoint mp;
    if (media.Track(o, d, 0, 4, &rng, &beta, &L, &t, &mp) == TrackEvent::kNone) ++survived;
  }
  const double delta_T = static_cast<double>(survived) / m;
  EXPECT_NEAR(delta_T, expected, 0.02 * expected);
  RecordProperty("delta_tracking_rel_err", std::to_string(delta_T / expected - 1));
}

TEST(MediaTransmittanceTest, TiersAgreeBehindDensityRamp) {
  // the ramp (along x) fills the view; the emissive wall is behind it.
  const double a = 0.5, b = 0.4, half = 1.0, sigma = 1.5;
  const int nx = 32;
  const float Le = 3.0f;
  const SceneDescription s = EmissiveWallScene(3.5, Le);
  EffectsFrame fx;
  fx.grid_media.push_back(RampGrid({1.5, 0, 0}, {half, 2, 2}, nx, a, b, sigma, 0.0f));
  const CameraView view = MakeView(CameraLookingAlongX(), kW, kH, kFovy, true, false, false);
  double mean[2];
  int k = 0;
  for (RenderSettings::Tier tier :
       {RenderSettings::Tier::kRealtime, RenderSettings::Tier::kPathtraced}) {
    auto r = MakeRenderer(s, TierSettings(tier, 256));
    RenderedFrame f;
    r->Render(IdentitySnapshot(s), &fx, view, &f);
    mean[k++] = MeanRadiance(f.radiance, 0, kW, 0, kH);
  }
  // reference for the centre ray (off-axis rays are up to 2.7 % longer in the box).
  const double centre = Le * std::exp(-sigma * RampIntegral(half, nx, a, b));
  EXPECT_NEAR(mean[0], mean[1], 0.02 * mean[1]);
  EXPECT_NEAR(mean[0], centre, 0.03 * centre);
  RecordProperty("realtime_over_pathtraced", std::to_string(mean[0] / mean[1]));
}

TEST(MediaTransmittanceTest, GridEmissionIntegratesAlongTheRay) {
  // a uniform emissive, absorbing grid (fire) in front of a black background: a ray crossing
  // length l of it gains emission (1 - exp(-sigma_t l)) / sigma_t.
  const SceneDescription s = EmptyScene();
  GridMedium g = RampGrid({2, 0, 0}, {1, 3, 3}, 4, 0.5f, 0.0f, 1.0f, 0.0f);
  auto e = std::make_shared<std::vector<float>>(4 * 2 * 2 * 3);
  for (size_t i = 0; i < e->size(); i += 3) (*e)[i] = 2.0f, (*e)[i + 1] = 1.0f, (*e)[i + 2] = 0.5f;
  g.emission = e;
  EffectsFrame fx;
  fx.grid_media.push_back(g);
  const CameraView view = MakeView(CameraLookingAlongX(), kW, kH, kFovy, true, false, false);
  double expected = 0;
  for (int v = 0; v < kH; ++v)
    for (int u = 0; u < kW; ++u) {
      const double l = RangeOfPixel(view.intrinsics, u, v, 2.0);  // 2 m of grid along x
      expected += 1.0 * (1 - std::exp(-0.5 * l)) / 0.5;
    }
  expected /= kW * kH;
  for (RenderSettings::Tier tier :
       {RenderSettings::Tier::kRealtime, RenderSettings::Tier::kPathtraced}) {
    auto r = MakeRenderer(s, TierSettings(tier, 128));
    RenderedFrame f;
    r->Render(IdentitySnapshot(s), &fx, view, &f);
    const double got = MeanRadiance(f.radiance, 0, kW, 0, kH, 1);
    EXPECT_NEAR(got, expected, 0.02 * expected) << static_cast<int>(tier);
    // the channels keep the emission's colour.
    EXPECT_NEAR(MeanRadiance(f.radiance, 0, kW, 0, kH, 0), 2 * got, 0.02 * 2 * got);
    RecordProperty(std::string("emission_ratio_") +
                       (tier == RenderSettings::Tier::kRealtime ? "realtime" : "pathtraced"),
                   std::to_string(got / expected));
  }
}

TEST(MediaTransmittanceTest, MalformedGridThrowsConfigError) {
  EffectsFrame fx;
  GridMedium g = RampGrid({0, 0, 0}, {1, 1, 1}, 4, 1, 0, 1, 0);
  g.nx = 5;  // does not match the array
  fx.grid_media.push_back(g);
  MediaScene media;
  try {
    media.Build(&fx);
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "effects.grid_media[0].density");
  }
  fx.grid_media.clear();
  fx.homogeneous_media.push_back(Fog(0.1f, 1.5f));
  EXPECT_THROW(media.Build(&fx), ConfigError);
}

}  // namespace
}  // namespace penumbra
