// the lane instantiation of the horizon test of lights with an extent
// (LightStraddlesHorizonOf<Lanes, LaneMask>) agrees with the scalar one (LightStraddlesHorizon)
// lane by lane: random cosines and
// angular radii, the boundary cases cos^2 == sin^2 and cos == sin sigma, points (sin^2 = 0),
// negative, infinite and NaN inputs.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "penumbra/core/rng.h"
#include "penumbra/render/light/lamp_math.h"
#include "penumbra/render/shading_lanes.h"

namespace penumbra {
namespace {

TEST(LightLanesTest, StraddlesHorizonLanesEqualsTheScalarTest) {
  Rng rng(37);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  // boundary values a random draw would not hit: exact ties of the two comparisons
  std::vector<float> special_cos = {0.0f, -0.0f, 1.0f, -1.0f, 1e-7f, 0.5f, nan, inf, -inf};
  auto uniform = [&](float lo, float hi) { return lo + (hi - lo) * rng.Uniform(); };
  auto pick = [&](int n) { return static_cast<int>(rng.NextU64() % static_cast<uint64_t>(n)); };
  int straddling = 0, total = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    Lanes cos_t, sin2, sin_sigma;
    for (int k = 0; k < kLanes; ++k) {
      const float s = uniform(0.0f, 0.3f);  // sin sigma
      float c = uniform(-0.4f, 0.4f);
      float s2 = s * s;
      float ss = std::sqrt(s2);
      switch (pick(10)) {
        case 0:  // cos == sin sigma exactly
          c = ss;
          break;
        case 1:  // cos^2 == sin^2 exactly (sin^2 taken as the rounded square)
          s2 = c * c;
          ss = std::sqrt(s2);
          break;
        case 2:  // a point light
          s2 = 0.0f, ss = 0.0f;
          break;
        case 3:
          c = special_cos[pick(static_cast<int>(special_cos.size()))];
          break;
        case 4:
          s2 = pick(2) ? nan : -s2;
          break;
        case 5:
          ss = nan;
          break;
        default:
          break;
      }
      cos_t[k] = c, sin2[k] = s2, sin_sigma[k] = ss;
    }
    const LaneMask lanes = LightStraddlesHorizonOf<Lanes, LaneMask>(cos_t, sin2, sin_sigma);
    for (int k = 0; k < kLanes; ++k) {
      const bool scalar = LightStraddlesHorizon(cos_t[k], sin2[k], sin_sigma[k]);
      ASSERT_EQ(lanes[k], scalar) << "cos " << cos_t[k] << " sin^2 " << sin2[k] << " sin "
                                  << sin_sigma[k];
      straddling += scalar;
      ++total;
    }
  }
  // both answers occur often enough for the comparison to mean something
  EXPECT_GT(straddling, total / 20);
  EXPECT_LT(straddling, total - total / 20);
}

}  // namespace
}  // namespace penumbra
