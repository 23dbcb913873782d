// ExpRn (core/exp_rn.h): e^x rounded to float from IEEE double operations only. on the CPU it
// is e^x correctly rounded (within an ulp everywhere, equal almost everywhere) with the stated
// limits; tests/render/cuda/cuda_backend_gpu_test.cc checks the device's bits against these.

#include "penumbra/core/exp_rn.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

namespace penumbra {
namespace {

// the float's bits as an ordered integer (so that adjacent floats differ by 1)
int64_t OrderedBits(float f) {
  int32_t i;
  std::memcpy(&i, &f, sizeof(i));
  return i < 0 ? -static_cast<int64_t>(i & 0x7fffffff) : static_cast<int64_t>(i);
}

TEST(ExpRn, IsTheCorrectlyRoundedExponentialAlmostEverywhere) {
  // 2^21 arguments evenly over [-104, 88.7] and every float of [-1, 1] near 0 in steps
  const int n = 1 << 21;
  int differ = 0;
  int64_t worst = 0;
  for (int i = 0; i <= n; ++i) {
    const float x = -104.0f + (88.7f + 104.0f) * static_cast<float>(i) / n;
    // reference: e^x in double (within an ulp of double), rounded once to float
    const float want = static_cast<float>(std::exp(static_cast<double>(x)));
    const float got = ExpRn(x);
    const int64_t d = std::llabs(OrderedBits(got) - OrderedBits(want));
    worst = std::max(worst, d);
    if (d != 0) ++differ;
  }
  EXPECT_LE(worst, 1) << "ExpRn strays more than an ulp from e^x";
  EXPECT_LE(differ, 4) << "ExpRn differs from the correctly rounded e^x at " << differ << " of "
                       << n + 1 << " arguments";
}

TEST(ExpRn, SmallArgumentsAndTheRainCullingsRange) {
  // the culling's arguments: minus optical depths in [0, 20]; and tiny ones, e^x ~ 1 + x
  for (float x = -20.0f; x <= 0.0f; x += 1.0f / 1024) {
    const float want = static_cast<float>(std::exp(static_cast<double>(x)));
    EXPECT_LE(std::llabs(OrderedBits(ExpRn(x)) - OrderedBits(want)), 1) << x;
  }
  EXPECT_EQ(ExpRn(0.0f), 1.0f);
  EXPECT_EQ(ExpRn(-0.0f), 1.0f);
  EXPECT_EQ(ExpRn(1e-30f), 1.0f);
  EXPECT_EQ(ExpRn(1.0f), static_cast<float>(std::exp(1.0)));
  EXPECT_EQ(ExpRn(-1.0f), static_cast<float>(std::exp(-1.0)));
}

TEST(ExpRn, LimitsAndNonFiniteArguments) {
  const float inf = std::numeric_limits<float>::infinity();
  EXPECT_EQ(ExpRn(inf), inf);
  EXPECT_EQ(ExpRn(-inf), 0.0f);
  EXPECT_TRUE(std::isnan(ExpRn(std::numeric_limits<float>::quiet_NaN())));
  EXPECT_EQ(ExpRn(89.0f), inf);
  EXPECT_EQ(ExpRn(88.72f),
            static_cast<float>(std::exp(static_cast<double>(88.72f))));  // below FLT_MAX
  EXPECT_EQ(ExpRn(88.75f), inf);                                         // just past it
  EXPECT_EQ(ExpRn(-200.0f), 0.0f);
  // subnormal results round as the double's conversion does
  EXPECT_EQ(ExpRn(-100.0f), static_cast<float>(std::exp(-100.0)));
  EXPECT_GT(ExpRn(-100.0f), 0.0f);
  EXPECT_EQ(ExpRn(-104.5f), 0.0f);
}

}  // namespace
}  // namespace penumbra
