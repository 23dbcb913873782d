// the realtime media's light volumes built over CudaRayQuery (their shadow rays traced on the
// GPU in batches, RayQuery::Occluded) against Embree's on the bundled fog, height-fog and dust
// worlds at 1 s (media_volumes.h): the CUDA backend can build a frame's volumes with the shared
// CPU code over its own BVH. ctest label `gpu`; "skipped: no CUDA device" without one.

#include <gtest/gtest.h>

#include <cstdio>
#include <memory>

#include "media_volumes.h"
#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/render/cuda/cuda_ray_query.h"

namespace penumbra {
namespace {

class MediaVolumesGpu : public ::testing::TestWithParam<const char*> {};

TEST_P(MediaVolumesGpu, CudaRayQueryVolumesMatchEmbrees) {
  if (!ProbeCudaDevice().available) GTEST_SKIP() << "skipped: no CUDA device";
  bool ok = false;
  const media_volumes::Compared c = media_volumes::CompareWithEmbree(
      GetParam(), [](const SceneDescription& s) { return std::make_unique<cuda::CudaRayQuery>(s); },
      &ok);
  ASSERT_TRUE(ok) << GetParam() << ": no homogeneous medium at 1 s";
  std::printf(
      "%s at 1 s: %zu visibility entries (%d lit), %d differ between Embree and the GPU; view "
      "rays to 20 m: max |dT| %.3g, max |dL| %.3g of max L %.3g\n",
      GetParam(), c.entries, c.lit, c.differ, c.max_dT, c.max_dL, c.max_L);
  EXPECT_GT(c.entries, 1000u);
  EXPECT_GT(c.lit, 0);
  // the GPU contracts multiply-adds: a grazing shadow ray may decide the other way
  EXPECT_LE(c.differ, static_cast<int>(c.entries / 200));
  EXPECT_EQ(c.max_dT, 0.0);
  EXPECT_GT(c.max_L, 0.0);
  EXPECT_LE(c.max_dL, 0.02 * c.max_L);
}

INSTANTIATE_TEST_SUITE_P(EffectsWorlds, MediaVolumesGpu,
                         ::testing::Values("effects/fog.yaml", "effects/height_fog.yaml",
                                           "effects/dust.yaml"));

}  // namespace
}  // namespace penumbra
