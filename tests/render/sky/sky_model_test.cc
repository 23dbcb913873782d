#include "penumbra/render/sky/sky_model.h"

#include <gtest/gtest.h>

#include <cmath>

#include "penumbra/core/error.h"
#include "penumbra/core/rng.h"

namespace penumbra {
namespace {

constexpr double kPi = 3.14159265358979323846;

double Luminance(const Eigen::Vector3f& c) {
  return 0.2126729 * c.x() + 0.7151522 * c.y() + 0.0721750 * c.z();
}

Eigen::Vector3f UniformSphere(Rng* rng) {
  const double z = 1 - 2 * rng->UniformD();
  const double phi = 2 * kPi * rng->UniformD();
  const double r = std::sqrt(std::max(0.0, 1 - z * z));
  return Eigen::Vector3d(r * std::cos(phi), r * std::sin(phi), z).cast<float>();
}

// dense midpoint quadrature over the sphere of f(w) d omega.
template <typename F>
Eigen::Vector3d SphereQuadrature(F f, int rows = 512, int cols = 1024) {
  Eigen::Vector3d sum(0, 0, 0);
  for (int r = 0; r < rows; ++r) {
    const double t0 = r * kPi / rows, t1 = (r + 1) * kPi / rows, t = 0.5 * (t0 + t1);
    const double d_omega = (std::cos(t0) - std::cos(t1)) * 2 * kPi / cols;
    for (int c = 0; c < cols; ++c) {
      const double p = (c + 0.5) * 2 * kPi / cols;
      const Eigen::Vector3f w =
          Eigen::Vector3d(std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t))
              .cast<float>();
      sum += f(w) * d_omega;
    }
  }
  return sum;
}

Sky DaylightSky(double elevation_deg, double azimuth_deg, float turbidity = 3.0f) {
  Sky sky;
  sky.type = Sky::Type::kDaylight;
  const double e = elevation_deg * kPi / 180, a = azimuth_deg * kPi / 180;
  sky.sun_direction_W = {std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e)};
  sky.turbidity = turbidity;
  sky.zenith_luminance = 8000;
  return sky;
}

TEST(SkyModelTest, UniformSkyIrradianceIsPiTimesRadianceOnAnyNormal) {
  Sky sky;
  sky.type = Sky::Type::kUniform;
  sky.radiance = {0.5f, 1.0f, 2.0f};
  const SkyModel model(sky);
  Rng rng(HashKeys(1, 2));
  for (int i = 0; i < 2000; ++i) {
    Eigen::Vector3f n = UniformSphere(&rng);
    if (i < 6) n = Eigen::Vector3f::Zero(), n[i / 2] = (i % 2) ? -1.0f : 1.0f;
    const Eigen::Vector3f e = model.Irradiance(n);
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(e[k], kPi * sky.radiance[k], 0.005 * kPi * sky.radiance[k]);
    EXPECT_TRUE(model.Radiance(n).isApprox(sky.radiance));
  }
}

TEST(SkyModelTest, DaylightZenithLuminanceEqualsConfiguredValue) {
  for (double elevation : {10.0, 30.0, 60.0, 85.0}) {
    for (float turbidity : {2.0f, 3.0f, 6.0f, 10.0f}) {
      const Sky sky = DaylightSky(elevation, 40, turbidity);
      const SkyModel model(sky);
      const double lum = Luminance(model.Radiance({0, 0, 1}));
      EXPECT_NEAR(lum, sky.zenith_luminance, 1e-4 * sky.zenith_luminance)
          << "elevation " << elevation << " turbidity " << turbidity;
    }
  }
}

TEST(SkyModelTest, DaylightIsBrighterNearTheSunAndBlueAtTheZenith) {
  const Sky sky = DaylightSky(35, 60);
  const SkyModel model(sky);
  const Eigen::Vector3f sun = sky.sun_direction_W.cast<float>();
  // 10 degrees from the sun, and the mirror direction on the far side (same elevation).
  const double e = 35 * kPi / 180, d = 10 * kPi / 180;
  for (double az_deg : {60.0}) {
    const double a = az_deg * kPi / 180 + d;
    const Eigen::Vector3f near_sun(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a),
                                   std::sin(e));
    const Eigen::Vector3f opposite(-near_sun.x(), -near_sun.y(), near_sun.z());
    EXPECT_GT(Luminance(model.Radiance(near_sun)), 3 * Luminance(model.Radiance(opposite)));
  }
  EXPECT_GT(Luminance(model.Radiance(sun)), Luminance(model.Radiance({0, 0, 1})));
  // a clear sky is blue at the zenith: chromaticity x below the D65 white point (0.3127).
  const Eigen::Vector3f z = model.Radiance({0, 0, 1});
  EXPECT_GT(z.z(), z.x());
}

TEST(SkyModelTest, DaylightGroundIsConstantDiffuseBounceOfTheSky) {
  const SkyModel model(DaylightSky(40, 0));
  const Eigen::Vector3f g = model.Radiance({0.3f, 0.1f, -0.9486833f});
  EXPECT_TRUE(g.isApprox(model.Radiance({-0.7f, 0.7f, -0.14142136f}), 1e-6f));
  // ground radiance = 0.2 / pi * sky irradiance on an upward-facing surface.
  const Eigen::Vector3d e_up = SphereQuadrature([&](const Eigen::Vector3f& w) {
    return w.z() > 0 ? Eigen::Vector3d(model.Radiance(w).cast<double>() * w.z())
                     : Eigen::Vector3d(0, 0, 0);
  });
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(g[k], 0.2 / kPi * e_up[k], 0.005 * g[k]);
}

TEST(SkyModelTest, DaylightIrradianceMatchesDenseQuadrature) {
  const Sky sky = DaylightSky(25, -30, 4.0f);
  const SkyModel model(sky);
  const Eigen::Vector3f normals[] = {{0, 0, 1},
                                     {0, 0, -1},
                                     {1, 0, 0},
                                     sky.sun_direction_W.cast<float>(),
                                     Eigen::Vector3f(-1, 1, 0.3f).normalized(),
                                     Eigen::Vector3f(0.2f, -0.5f, -0.4f).normalized()};
  for (const Eigen::Vector3f& n : normals) {
    const Eigen::Vector3d ref = SphereQuadrature([&](const Eigen::Vector3f& w) {
      return Eigen::Vector3d(model.Radiance(w).cast<double>() * std::max(0.0f, n.dot(w)));
    });
    const Eigen::Vector3f e = model.Irradiance(n);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(e[k], ref[k], 0.01 * ref[k]) << n.transpose();
  }
}

TEST(SkyModelTest, SampleAndPdfAreConsistent) {
  for (const Sky& sky : {DaylightSky(50, 120), DaylightSky(5, 200, 8.0f)}) {
    const SkyModel model(sky);
    // the pdf integrates to one.
    const Eigen::Vector3d pdf_integral = SphereQuadrature(
        [&](const Eigen::Vector3f& w) { return Eigen::Vector3d::Constant(model.Pdf(w)); });
    EXPECT_NEAR(pdf_integral.x(), 1.0, 1e-3);
    // monte carlo estimate of the integral of radiance over the sphere with Sample/Pdf.
    Rng rng(HashKeys(7, 11));
    const int n = 200000;
    Eigen::Vector3d mc(0, 0, 0);
    for (int i = 0; i < n; ++i) {
      float pdf = 0;
      const Eigen::Vector3f w = model.Sample(rng.Uniform(), rng.Uniform(), &pdf);
      ASSERT_NEAR(w.norm(), 1.0f, 1e-5f);
      ASSERT_GT(pdf, 0.0f);
      ASSERT_NEAR(model.Pdf(w), pdf, 1e-3f * pdf);
      mc += model.Radiance(w).cast<double>() / pdf;
    }
    mc /= n;
    const Eigen::Vector3d ref = SphereQuadrature([&](const Eigen::Vector3f& w) {
      return Eigen::Vector3d(model.Radiance(w).cast<double>());
    });
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(mc[k], ref[k], 0.01 * ref[k]);
  }
}

TEST(SkyModelTest, BadDaylightParametersThrowConfigError) {
  Sky sky = DaylightSky(30, 0);
  sky.turbidity = 1.0f;
  EXPECT_THROW(SkyModel{sky}, ConfigError);
  sky.turbidity = 12.0f;
  EXPECT_THROW(SkyModel{sky}, ConfigError);
  sky.turbidity = 3.0f;
  sky.sun_direction_W = {0, 0, 0};
  EXPECT_THROW(SkyModel{sky}, ConfigError);
}

}  // namespace
}  // namespace penumbra
