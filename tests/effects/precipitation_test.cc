// rain drops against the Marshall-Palmer distribution and the terminal-velocity fit; snow.
#include "penumbra/effects/precipitation.h"

#include <gtest/gtest.h>

#include <cmath>

namespace penumbra {
namespace {

// numerical integrals of the truncated Marshall-Palmer distribution (computed here, not by
// the library): N_total = int N(D) dD and mean v = int v(D) N(D) dD / N_total over
// [0.1, 6] mm, trapezoid with 0.0005 mm steps.
struct MpIntegrals {
  double n_total = 0, mean_v = 0;
};
MpIntegrals Integrate(double rate_mm_h) {
  const double n0 = 8000, lam = 4.1 * std::pow(rate_mm_h, -0.21);
  const double a = 0.1, b = 6.0, h = 0.0005;
  const int n = static_cast<int>(std::lround((b - a) / h));
  double sn = 0, sv = 0;
  for (int i = 0; i <= n; ++i) {
    const double d = a + i * h;
    const double w = (i == 0 || i == n) ? 0.5 : 1.0;
    const double nd = n0 * std::exp(-lam * d);
    const double v = std::max(0.0, 9.65 - 10.3 * std::exp(-0.6 * d));
    sn += w * nd * h;
    sv += w * v * nd * h;
  }
  return {sn, sv / sn};
}

class RainTest : public ::testing::TestWithParam<double> {};

TEST_P(RainTest, NumberDensityAndFallSpeedFollowMarshallPalmer) {
  const double rate = GetParam();
  const MpIntegrals ref = Integrate(rate);
  RainParams p;
  p.rate_mm_h = rate;
  p.box_half_extents_m = {2.0, 2.0, 1.5};
  p.max_particles = 5000000;
  const Eigen::Vector3d viewer(1.0, -2.0, 1.7);
  const ParticleSet s = SampleRain(p, 3.7, viewer, 1.0, nullptr, 42, 7);
  const double volume = 4.0 * 4.0 * 3.0;
  const double density = s.position_W.size() / volume;
  EXPECT_NEAR(density, ref.n_total, 0.05 * ref.n_total);
  // a sub-box (the central eighth) holds its share: the drops fill the box uniformly
  size_t inner = 0;
  double v_sum = 0;
  for (size_t i = 0; i < s.position_W.size(); ++i) {
    const Eigen::Vector3d d = s.position_W[i].cast<double>() - viewer;
    ASSERT_LE(std::abs(d.x()), 2.0 + 1e-5);
    ASSERT_LE(std::abs(d.z()), 1.5 + 1e-5);
    if (std::abs(d.x()) < 1.0 && std::abs(d.y()) < 1.0 && std::abs(d.z()) < 0.75) ++inner;
    v_sum += -s.velocity_W[i].z();
    ASSERT_GE(s.radius_m[i], 0.05e-3 - 1e-9);
    ASSERT_LE(s.radius_m[i], 3e-3 + 1e-9);
  }
  EXPECT_NEAR(inner / (volume / 8.0), ref.n_total, 0.05 * ref.n_total);
  const double mean_v = v_sum / s.position_W.size();
  EXPECT_NEAR(mean_v, ref.mean_v, 0.05 * ref.mean_v);
  RecordProperty("n_total_ref", std::to_string(ref.n_total));
  RecordProperty("n_total_sampled", std::to_string(density));
  RecordProperty("mean_v_ref", std::to_string(ref.mean_v));
  RecordProperty("mean_v_sampled", std::to_string(mean_v));
  std::printf("rain %g mm/h: N %.1f vs %.1f /m^3, inner %.1f, mean v %.4f vs %.4f m/s\n", rate,
              density, ref.n_total, inner / (volume / 8.0), mean_v, ref.mean_v);
  // the library's closed form agrees with the numerical integral
  EXPECT_NEAR(RainNumberDensity(rate, 0.1, 6.0), ref.n_total, 1e-3 * ref.n_total);
}

INSTANTIATE_TEST_SUITE_P(Rates, RainTest, ::testing::Values(5.0, 50.0));

TEST(RainStationarityTest, CountIsStationaryAndDropsFall) {
  RainParams p;
  p.rate_mm_h = 10;
  p.box_half_extents_m = {1, 1, 1};
  p.wind_m_s = {2, 0, 0};
  const ParticleSet a = SampleRain(p, 0.0, {0, 0, 0}, 1.0, nullptr, 1, 1);
  const ParticleSet b = SampleRain(p, 0.01, {0, 0, 0}, 1.0, nullptr, 1, 1);
  const ParticleSet c = SampleRain(p, 1000.0, {5, 5, 5}, 1.0, nullptr, 1, 1);
  ASSERT_EQ(a.position_W.size(), b.position_W.size());
  EXPECT_EQ(a.position_W.size(), c.position_W.size());
  // between nearby times each drop moves by v dt (unless it wrapped)
  int moved = 0;
  for (size_t i = 0; i < a.position_W.size(); ++i) {
    const Eigen::Vector3f d = b.position_W[i] - a.position_W[i];
    if ((d - 0.01f * a.velocity_W[i]).norm() < 1e-4f) ++moved;
  }
  EXPECT_GT(moved, 0.9 * a.position_W.size());
  // same seed -> identical; other seed -> different
  const ParticleSet a2 = SampleRain(p, 0.0, {0, 0, 0}, 1.0, nullptr, 1, 1);
  EXPECT_EQ(a.position_W, a2.position_W);
  const ParticleSet a3 = SampleRain(p, 0.0, {0, 0, 0}, 1.0, nullptr, 2, 1);
  EXPECT_NE(a.position_W, a3.position_W);
  // half weight keeps about half the drops
  const ParticleSet h = SampleRain(p, 0.0, {0, 0, 0}, 0.5, nullptr, 1, 1);
  EXPECT_NEAR(static_cast<double>(h.position_W.size()) / a.position_W.size(), 0.5, 0.03);
}

TEST(RainStationarityTest, MaxParticlesShrinksTheBoxKeepingTheDensity) {
  RainParams p;
  p.rate_mm_h = 50;
  p.box_half_extents_m = {4, 4, 3};
  p.max_particles = 20000;
  const ParticleSet s = SampleRain(p, 1.0, {0, 0, 0}, 1.0, nullptr, 3, 1);
  EXPECT_NEAR(static_cast<double>(s.position_W.size()), 20000.0, 2.0);
  const Eigen::Vector3d half =
      EffectiveHalfExtents(p.box_half_extents_m, RainNumberDensity(50, 0.1, 6), 20000);
  EXPECT_NEAR(s.position_W.size() / (8.0 * half.prod()), RainNumberDensity(50, 0.1, 6), 1.0);
}

TEST(SnowTest, NumberDensityFromWaterEquivalentRate) {
  SnowParams p;
  p.rate_mm_h = 2;
  p.flake_diameter_mm = 5;
  p.flake_density_kg_m3 = 100;
  p.box_half_extents_m = {3, 3, 3};
  // n = (R / 3600 kg m^-2 s^-1) / (rho_f pi D^3 / 6 x 0.81 D^0.16)
  const double m = 100 * M_PI * std::pow(5e-3, 3) / 6;
  const double n_ref = (2.0 / 3600.0) / (m * 0.81 * std::pow(5.0, 0.16));
  EXPECT_NEAR(SnowNumberDensity(p), n_ref, 1e-9 * n_ref);
  const ParticleSet s = SampleSnow(p, 2.0, {0, 0, 0}, 1.0, nullptr, 5, 2);
  EXPECT_NEAR(s.position_W.size() / 216.0, n_ref, 0.02 * n_ref + 1.0 / 216);
  double vz = 0, vh = 0;
  for (const auto& v : s.velocity_W) {
    vz += v.z();
    vh += std::hypot(v.x(), v.y());
  }
  vz /= s.velocity_W.size();
  vh /= s.velocity_W.size();
  EXPECT_LT(vz, -0.8);  // falls at ~1 m/s
  EXPECT_GT(vz, -1.3);
  EXPECT_GT(vh, 0.05);  // turbulent drift
}

// PlaceParticles spreads chunks of the table over a pool: the particles and their order must
// not depend on it (rain and drifting snow, thinned and clipped to a region).
TEST(PlaceParticlesTest, PoolGivesTheSerialResultBitForBit) {
  RainParams rain;
  rain.rate_mm_h = 25;
  rain.max_particles = 70000;
  SnowParams snow;
  snow.rate_mm_h = 5;
  snow.max_particles = 40000;
  const PrecipitationTable tables[2] = {BuildRainTable(rain, 9, 1), BuildSnowTable(snow, 9, 2)};
  const BoxRegion region{{-3, -2, -1}, {2, 3, 1.5}};
  ThreadPool pool2(2), pool3(3);
  for (const PrecipitationTable& tab : tables) {
    ASSERT_GT(tab.q0.size(), 30000u);  // several chunks
    for (const BoxRegion* r : {static_cast<const BoxRegion*>(nullptr), &region}) {
      const ParticleSet serial = PlaceParticles(tab, 2.5, {1, 2, 0.5}, 0.7, r);
      ASSERT_GT(serial.position_W.size(), 1000u);
      for (ThreadPool* pool : {&pool2, &pool3}) {
        const ParticleSet par = PlaceParticles(tab, 2.5, {1, 2, 0.5}, 0.7, r, pool);
        EXPECT_EQ(par.position_W, serial.position_W);
        EXPECT_EQ(par.velocity_W, serial.velocity_W);
        EXPECT_EQ(par.radius_m, serial.radius_m);
        EXPECT_EQ(par.kind, serial.kind);
      }
    }
  }
}

}  // namespace
}  // namespace penumbra
