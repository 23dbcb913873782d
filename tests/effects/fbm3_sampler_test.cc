// Fbm3Sampler (effects/value_noise.h) memoises lattice cells: it must give Fbm3's values bit for
// bit along a voxel-grid walk (cells reused, revisited and skipped) and for negative coordinates.

#include <gtest/gtest.h>

#include "penumbra/effects/value_noise.h"

namespace penumbra {
namespace {

TEST(Fbm3SamplerTest, EqualsFbm3BitForBit) {
  for (int octaves : {1, 4, 6}) {
    Fbm3Sampler sampler(1234, octaves);
    int checked = 0;
    for (int k = 0; k < 5; ++k)
      for (int j = 0; j < 7; ++j)
        for (int i = 0; i < 23; ++i) {
          const Eigen::Vector3d q(-3.1 + 0.173 * i, -0.7 + 0.29 * j, 2.05 - 0.61 * k);
          ASSERT_EQ(sampler(q), Fbm3(1234, q, octaves)) << q.transpose();
          ++checked;
        }
    // back to an earlier cell, then a far jump.
    for (const Eigen::Vector3d& q :
         {Eigen::Vector3d(-3.0, -0.6, 2.0), Eigen::Vector3d(1e3, -2e3, 7.5)})
      EXPECT_EQ(sampler(q), Fbm3(1234, q, octaves));
    EXPECT_EQ(checked, 5 * 7 * 23);
  }
}

}  // namespace
}  // namespace penumbra
