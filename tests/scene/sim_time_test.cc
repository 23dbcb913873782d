// scene/sim_time.h: the physics rate of a timestep and the exact time of each step.

#include "penumbra/scene/sim_time.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>

namespace penumbra {
namespace {

TEST(SimTimeOfStep, IsTheSmallestDoubleAtOrAboveTheExactStepTime) {
  for (double dt : {0.002, 0.005, 0.001, 0.01, 0.1, 0.003, 1.0 / 60.0, 0.0015}) {
    const double rate = PhysicsRateHz(dt);
    const bool integer_rate = rate == std::nearbyint(rate);
    for (int64_t n = 0; n <= 200000; n += (n < 2000 ? 1 : 97)) {
      const double t = SimTimeOfStep(n, dt);
      const double nd = static_cast<double>(n);
      // exact comparisons of t against n / R (or n dt) through fma
      if (integer_rate) {
        ASSERT_GE(std::fma(t, rate, -nd), 0) << dt << " " << n;
        if (n > 0) {
          ASSERT_LT(std::fma(std::nextafter(t, 0.0), rate, -nd), 0) << dt << " " << n;
        }
      } else {
        ASSERT_GE(std::fma(-nd, dt, t), 0) << dt << " " << n;
        if (n > 0) {
          ASSERT_LT(std::fma(-nd, dt, std::nextafter(t, 0.0)), 0) << dt << " " << n;
        }
      }
    }
  }
  EXPECT_EQ(PhysicsRateHz(0.002), 500.0);
  EXPECT_EQ(SimTimeOfStep(0, 0.002), 0.0);
  EXPECT_EQ(SimTimeOfStep(-3, 0.002), 0.0);
}

}  // namespace
}  // namespace penumbra
