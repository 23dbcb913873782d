// the realtime media's light volumes (render/media_realtime.h) built over the CUDA backend's
// traversal instead of Embree: RealtimeMedia takes any RayQuery, so the CUDA backend can build
// a frame's volumes with the CPU code over its own BVH. here BvhRayQuery (the kernels'
// PB_HOST_DEVICE traversal run on the host, the reference of CudaRayQuery) against the CPU
// renderer's RayScene on the bundled fog, height-fog and dust worlds at 1 s: the world light
// volume's visibility entries and the camera rays' media terms agree but for shadow rays that
// graze an edge. no GPU needed.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>

#include "penumbra/render/camera.h"
#include "penumbra/render/cuda/bvh_ray_query.h"
#include "penumbra/render/embree/ray_scene.h"
#include "penumbra/render/light_sampler.h"
#include "penumbra/render/media_realtime.h"
#include "penumbra/render/media_scene.h"
#include "realtime_parity.h"

namespace penumbra {
namespace {

class MediaVolumesOverBvh : public ::testing::TestWithParam<const char*> {};

TEST_P(MediaVolumesOverBvh, MatchEmbreesVolumes) {
  const std::unique_ptr<Session> session = realtime_parity::LoadSimulatedAt(GetParam(), 1.0);
  const SceneDescription& scene = session->scene();
  const WorldSnapshot snap = session->sim().Snapshot();
  constexpr int W = 96, H = 72;
  const CameraView view = realtime_parity::RgbDepthView(scene, snap, W, H);
  const std::shared_ptr<const EffectsFrame> fx =
      session->effects().Evaluate(snap, view.X_WO.translation());
  ASSERT_TRUE(fx && !fx->homogeneous_media.empty()) << GetParam();
  MediaScene media;
  media.Build(fx.get());
  LightSampler lights(scene);
  lights.Update(snap, fx.get());
  ASSERT_GT(lights.size(), 0);
  RayScene embree(scene);
  embree.Update(snap);
  cuda::BvhRayQuery bvh(scene);
  bvh.Update(snap);
  const Camera camera(view.X_WO, view.intrinsics);
  const Eigen::Vector3f centre = scene.center_W.cast<float>();
  const Eigen::Vector3f sky = Eigen::Vector3f::Constant(0.5f);
  ThreadPool pool(2);
  RealtimeMedia a, b;
  a.Build(media, lights, embree, camera, 77, centre, scene.extent_m, sky, nullptr, &pool);
  b.Build(media, lights, bvh, camera, 77, centre, scene.extent_m, sky, nullptr, &pool);
  const std::vector<float>& va = a.light_volume_visibility();
  const std::vector<float>& vb = b.light_volume_visibility();
  ASSERT_EQ(va.size(), vb.size());
  ASSERT_GT(va.size(), 1000u);
  int differ = 0, seen = 0;
  for (size_t i = 0; i < va.size(); ++i) {
    differ += va[i] != vb[i] ? 1 : 0;
    seen += va[i] > 0 ? 1 : 0;
  }
  // the camera rays' transmittance and added radiance to a far point
  double max_dT = 0, max_dL = 0, max_L = 0;
  for (int v = 0; v < H; v += 3) {
    for (int u = 0; u < W; u += 3) {
      const Ray r = camera.GenerateRay(static_cast<float>(u), static_cast<float>(v));
      const Eigen::Vector3f d = r.d.normalized();
      const MediaSegment sa = a.IntegrateView(lights, r.o, d, 20.0f, u, v);
      const MediaSegment sb = b.IntegrateView(lights, r.o, d, 20.0f, u, v);
      max_dT = std::max(max_dT, static_cast<double>((sa.T - sb.T).cwiseAbs().maxCoeff()));
      max_dL = std::max(max_dL, static_cast<double>((sa.L_add - sb.L_add).cwiseAbs().maxCoeff()));
      max_L = std::max(max_L, static_cast<double>(sa.L_add.maxCoeff()));
    }
  }
  std::printf(
      "%s at 1 s: %zu visibility entries (%d lit), %d differ between Embree and the BVH; view "
      "rays to 20 m: max |dT| %.3g, max |dL| %.3g of max L %.3g\n",
      GetParam(), va.size(), seen, differ, max_dT, max_dL, max_L);
  EXPECT_GT(seen, 0);
  EXPECT_LE(differ, static_cast<int>(va.size() / 200));  // 0.5 %: grazing shadow rays
  EXPECT_EQ(max_dT, 0.0);                                // the transmittance has no shadow rays
  EXPECT_GT(max_L, 0.0);
  EXPECT_LE(max_dL, 0.02 * max_L);
}

INSTANTIATE_TEST_SUITE_P(EffectsWorlds, MediaVolumesOverBvh,
                         ::testing::Values("effects/fog.yaml", "effects/height_fog.yaml",
                                           "effects/dust.yaml"));

}  // namespace
}  // namespace penumbra
