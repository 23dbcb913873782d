// blackbody colour and luminance against an independent numerical integration.
#include "penumbra/effects/blackbody.h"

#include <gtest/gtest.h>

#include <cmath>

namespace penumbra {
namespace {

// independent path: Planck's law with the radiation constants c1L = 2hc^2 and c2 = hc/k,
// the Wyman-Sloan-Shirley 2013 multi-lobe CIE 1931 fit written out again, and the
// trapezoid rule over 380-780 nm at 1 nm.
double G(double x, double mu, double a, double b) {
  const double s = x < mu ? a : b;
  return std::exp(-0.5 * (x - mu) * (x - mu) / (s * s));
}

Eigen::Vector3d ReferenceXyz(double T) {
  const double c1l = 1.191042972e-16;  // W m^2 sr^-1
  const double c2 = 1.438776877e-2;    // m K
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int nm = 380; nm <= 780; ++nm) {
    const double l = nm * 1e-9;
    const double b = c1l / std::pow(l, 5) / (std::exp(c2 / (l * T)) - 1.0) * 1e-9;
    const Eigen::Vector3d cmf(1.056 * G(nm, 599.8, 37.9, 31.0) + 0.362 * G(nm, 442.0, 16.0, 26.7) -
                                  0.065 * G(nm, 501.1, 20.4, 26.2),
                              0.821 * G(nm, 568.8, 46.9, 40.5) + 0.286 * G(nm, 530.9, 16.3, 31.1),
                              1.217 * G(nm, 437.0, 11.8, 36.0) + 0.681 * G(nm, 459.0, 26.0, 13.8));
    const double wgt = (nm == 380 || nm == 780) ? 0.5 : 1.0;
    sum += wgt * b * cmf;
  }
  return sum;
}

Eigen::Vector3d ReferenceRgb(double T) {
  const Eigen::Vector3d xyz = ReferenceXyz(T);
  Eigen::Vector3d rgb(3.2406 * xyz.x() - 1.5372 * xyz.y() - 0.4986 * xyz.z(),
                      -0.9689 * xyz.x() + 1.8758 * xyz.y() + 0.0415 * xyz.z(),
                      0.0557 * xyz.x() - 0.2040 * xyz.y() + 1.0570 * xyz.z());
  rgb = rgb.cwiseMax(0.0);
  return rgb / rgb.maxCoeff();
}

TEST(BlackbodyTest, FlameTemperaturesMatchPlanckIntegral) {
  for (double T : {1000.0, 1500.0, 2000.0}) {
    SCOPED_TRACE("T = " + std::to_string(T));
    const Eigen::Vector3d xyz = BlackbodyXyz(T), ref = ReferenceXyz(T);
    // chromaticity (x, y) within 1%
    const double x = xyz.x() / xyz.sum(), y = xyz.y() / xyz.sum();
    const double xr = ref.x() / ref.sum(), yr = ref.y() / ref.sum();
    EXPECT_NEAR(x, xr, 0.01 * xr);
    EXPECT_NEAR(y, yr, 0.01 * yr);
    // colour within 0.01 per channel (max component 1)
    const Eigen::Vector3d rgb = BlackbodyLinearSrgb(T), rgb_ref = ReferenceRgb(T);
    std::printf(
        "%.0f K: rgb %.4f %.4f %.4f (reference %.4f %.4f %.4f), xy %.4f %.4f (ref %.4f %.4f), "
        "L %.4g cd/m^2\n",
        T, rgb.x(), rgb.y(), rgb.z(), rgb_ref.x(), rgb_ref.y(), rgb_ref.z(), x, y, xr, yr,
        BlackbodyLuminance(T));
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(rgb[c], rgb_ref[c], 0.01) << "channel " << c;
    // red-orange
    EXPECT_DOUBLE_EQ(rgb.x(), 1.0);
    EXPECT_GT(rgb.x(), rgb.y());
    EXPECT_GT(rgb.y(), rgb.z());
    // luminance within 1% of 683 lm/W x the y-bar integral
    EXPECT_NEAR(BlackbodyLuminance(T), 683.0 * ref.y(), 0.01 * 683.0 * ref.y());
    // the fast table within 0.5%
    EXPECT_NEAR(BlackbodyTable::Luminance(T), BlackbodyLuminance(T), 0.005 * BlackbodyLuminance(T));
    EXPECT_NEAR(BlackbodyTable::Color(T).x(), rgb.x(), 1e-3);
    EXPECT_NEAR(BlackbodyTable::Color(T).y(), rgb.y(), 1e-3);
  }
}

TEST(BlackbodyTest, PlanckianAt6504KIsNearlyWhite) {
  // D65's correlated colour temperature: the Planckian locus point is within a few
  // percent of the sRGB white (1, 1, 1); it lies slightly below D65 (a magenta tint, green
  // lowest: measured (1, 0.945, 0.994))
  const Eigen::Vector3d rgb = BlackbodyLinearSrgb(6504);
  std::printf("6504 K: rgb %.4f %.4f %.4f\n", rgb.x(), rgb.y(), rgb.z());
  EXPECT_GT(rgb.minCoeff(), 0.93) << rgb.transpose();
  const Eigen::Vector3d xyz = BlackbodyXyz(6504);
  EXPECT_NEAR(xyz.x() / xyz.sum(), 0.3135, 0.002);  // CIE 1931 Planckian locus at 6504 K
  EXPECT_NEAR(xyz.y() / xyz.sum(), 0.3237, 0.003);
}

TEST(BlackbodyTest, HotterIsBrighterAndBluer) {
  double prev_l = 0, prev_b = -1;
  for (double T = 800; T <= 4000; T += 400) {
    const double l = BlackbodyLuminance(T);
    const double b = BlackbodyLinearSrgb(T).z();
    EXPECT_GT(l, prev_l);
    EXPECT_GE(b, prev_b);
    prev_l = l;
    prev_b = b;
  }
}

}  // namespace
}  // namespace penumbra
