// the sRGB transfer functions (core/srgb.h) against values of IEC 61966-2-1's formulas.

#include "penumbra/core/srgb.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace penumbra {
namespace {

TEST(Srgb, EncodesKnownValues) {
  EXPECT_EQ(LinearToSrgb(0.0), 0.0);
  EXPECT_EQ(LinearToSrgb(0.0f), 0.0f);
  EXPECT_NEAR(LinearToSrgb(1.0), 1.0, 1e-15);
  EXPECT_FLOAT_EQ(LinearToSrgb(1.0f), 1.0f);
  // the linear segment below the knee: 12.92 l
  EXPECT_DOUBLE_EQ(LinearToSrgb(0.001), 12.92 * 0.001);
  EXPECT_FLOAT_EQ(LinearToSrgb(0.003f), 12.92f * 0.003f);
  // the knee: both segments meet at (0.0031308, 0.04045) to 1e-6
  EXPECT_NEAR(LinearToSrgb(0.0031308), 0.04045, 1e-6);
  EXPECT_NEAR(LinearToSrgb(std::nextafter(0.0031308, 1.0)), 0.04045, 1e-6);
  // 1.055 0.5^(1 / 2.4) - 0.055 and 1.055 0.18^(1 / 2.4) - 0.055
  EXPECT_NEAR(LinearToSrgb(0.5), 0.735357, 1e-6);
  EXPECT_NEAR(LinearToSrgb(0.5f), 0.735357f, 1e-6);
  EXPECT_NEAR(LinearToSrgb(0.18), 0.461356, 1e-6);
  EXPECT_EQ(std::lround(255 * LinearToSrgb(0.5)), 188);
}

TEST(Srgb, DecodesKnownValues) {
  EXPECT_EQ(SrgbToLinear(0.0), 0.0);
  EXPECT_EQ(SrgbToLinear(0.0f), 0.0f);
  EXPECT_EQ(SrgbToLinear(1.0), 1.0);
  EXPECT_FLOAT_EQ(SrgbToLinear(1.0f), 1.0f);
  // the linear segment below the knee: v / 12.92
  EXPECT_DOUBLE_EQ(SrgbToLinear(0.04), 0.04 / 12.92);
  EXPECT_FLOAT_EQ(SrgbToLinear(0.04f), 0.04f / 12.92f);
  EXPECT_NEAR(SrgbToLinear(0.04045), 0.0031308, 1e-6);
  // ((0.5 + 0.055) / 1.055)^2.4
  EXPECT_NEAR(SrgbToLinear(0.5), 0.2140411, 1e-7);
  EXPECT_NEAR(SrgbToLinear(0.5f), 0.2140411f, 1e-6);
  // linear 0.5 lies between 8-bit codes 187 and 188
  EXPECT_LT(SrgbToLinear(187 / 255.0), 0.5);
  EXPECT_GT(SrgbToLinear(188 / 255.0), 0.5);
}

TEST(Srgb, ClampsItsArgumentToTheUnitInterval) {
  EXPECT_EQ(LinearToSrgb(-0.5), 0.0);
  EXPECT_EQ(LinearToSrgb(2.0f), LinearToSrgb(1.0f));
  EXPECT_EQ(SrgbToLinear(-0.5f), 0.0f);
  EXPECT_EQ(SrgbToLinear(7.0), 1.0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(std::isnan(LinearToSrgb(nan)));
  EXPECT_TRUE(std::isnan(SrgbToLinear(nan)));
}

TEST(Srgb, DecodeInvertsEncode) {
  double worst_double = 0, worst_float = 0;
  for (int i = 0; i <= 100000; ++i) {
    const double l = i / 100000.0;
    worst_double = std::max(worst_double, std::abs(SrgbToLinear(LinearToSrgb(l)) - l));
    const float lf = static_cast<float>(l);
    worst_float =
        std::max(worst_float, static_cast<double>(std::abs(SrgbToLinear(LinearToSrgb(lf)) - lf)));
    // float evaluates the same formula: within float rounding of the double result
    EXPECT_NEAR(LinearToSrgb(lf), LinearToSrgb(static_cast<double>(lf)), 1e-6) << l;
  }
  EXPECT_LT(worst_double, 1e-12);
  EXPECT_LT(worst_float, 1e-6);
}

}  // namespace
}  // namespace penumbra
