// the realtime media's light volumes (render/media/media_realtime.h) built over the CUDA backend's
// traversal instead of Embree: RealtimeMedia takes any RayQuery, so the CUDA backend can build
// a frame's volumes with the CPU code over its own BVH. here BvhRayQuery (the kernels'
// PB_HOST_DEVICE traversal run on the host, the reference of CudaRayQuery) against the CPU
// renderer's RayScene on the bundled fog, height-fog and dust worlds at 1 s: the world light
// volume's visibility entries and the camera rays' media terms agree but for shadow rays that
// graze an edge (media_volumes.h). no GPU needed; media_volumes_gpu_test.cc runs the same over
// CudaRayQuery on the GPU.

#include "media_volumes.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <memory>

#include "penumbra/render/frame/bvh_ray_query.h"

namespace penumbra {
namespace {

class MediaVolumesOverBvh : public ::testing::TestWithParam<const char*> {};

TEST_P(MediaVolumesOverBvh, MatchEmbreesVolumes) {
  bool ok = false;
  const media_volumes::Compared c = media_volumes::CompareWithEmbree(
      GetParam(), [](const SceneDescription& s) { return std::make_unique<cuda::BvhRayQuery>(s); },
      &ok);
  ASSERT_TRUE(ok) << GetParam() << ": no homogeneous medium at 1 s";
  std::printf(
      "%s at 1 s: %zu visibility entries (%d lit), %d differ between Embree and the BVH; view "
      "rays to 20 m: max |dT| %.3g, max |dL| %.3g of max L %.3g\n",
      GetParam(), c.entries, c.lit, c.differ, c.max_dT, c.max_dL, c.max_L);
  EXPECT_GT(c.entries, 1000u);
  EXPECT_GT(c.lit, 0);
  EXPECT_LE(c.differ, static_cast<int>(c.entries / 200));  // 0.5 %: grazing shadow rays
  EXPECT_EQ(c.max_dT, 0.0);                                // the transmittance has no shadow rays
  EXPECT_GT(c.max_L, 0.0);
  EXPECT_LE(c.max_dL, 0.02 * c.max_L);
}

INSTANTIATE_TEST_SUITE_P(EffectsWorlds, MediaVolumesOverBvh,
                         ::testing::Values("effects/fog.yaml", "effects/height_fog.yaml",
                                           "effects/dust.yaml"));

}  // namespace
}  // namespace penumbra
