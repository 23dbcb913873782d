// the realtime path's penumbra refinement split over the lanes of a warp (as
// realtime_kernels.cu's WarpPenumbraRefiner shares it: lane k traces the lattice points
// kLightPenumbraRays + k, + k + 32, ...) gives every pixel the same radiance as the serial
// refinement, run here on the CPU over the host BVH (no GPU needed): the default room (lamps)
// and the house (the sun through windows) at 160x120, with pixels in a penumbra in both.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "penumbra/render/cuda/bvh_scene.h"
#include "penumbra/render/cuda/realtime_frame.h"
#include "realtime_parity.h"

namespace penumbra {
namespace {

// the warp's split of the lattice points, one simulated lane after the other; counts the
// pixel-lights it refined.
struct LaneSplitRefiner {
  int* refined;
  void operator()(const cuda::SceneView& s, const LightPod& l, bool need,
                  const cuda::PenumbraQuery& q, int* rays, int* visible) const {
    if (!need) return;
    ++*refined;
    for (int lane = 0; lane < 32; ++lane)
      cuda::CountLatticeVisibility(s, l, q, kLightPenumbraRays + lane,
                                   kLightStrata * kLightPenumbraRays, 32, rays, visible);
  }
};

class PenumbraLaneSplit : public ::testing::TestWithParam<std::string> {};

TEST_P(PenumbraLaneSplit, SameRadianceAsSerialRefinement) {
  const std::unique_ptr<Session> session = realtime_parity::LoadSimulated(GetParam());
  const SceneDescription& scene = session->scene();
  const WorldSnapshot snap = session->sim().Snapshot();
  const CameraView view = realtime_parity::RgbDepthView(scene, snap, 160, 120);
  cuda::BvhScene bvh(scene);
  bvh.Update(snap);
  RenderSettings settings;
  cuda::RealtimeFrameData data(scene, settings);
  ThreadPool pool(0);
  data.Prepare(snap, view, &pool);
  const cuda::PinholeCamera& c = data.camera();
  const int64_t n = static_cast<int64_t>(c.width) * c.height;
  const cuda::RealtimeFrameView geo = data.View(bvh.view(), nullptr);
  std::vector<cuda::PixelGeometry> geometry(n);
  std::vector<cuda::TraceHit> hits(n);
  for (int v = 0; v < c.height; ++v)
    for (int u = 0; u < c.width; ++u) {
      float t;
      const int64_t i = static_cast<int64_t>(v) * c.width + u;
      geometry[i] = cuda::PrimaryGeometry(geo, u, v, &t, &hits[i]);
    }
  std::vector<Float3> sky(n);
  data.SkyTerms(geometry.data(), n, sky.data(), &pool);
  const cuda::RealtimeFrameView f = data.View(bvh.view(), sky.data());
  // rows over the pool; each row counts its own refinements and differences
  std::vector<int> row_refined(c.height, 0), row_differ(c.height, 0);
  ParallelForOrSerial(&pool, c.height, [&](int64_t row) {
    const int v = static_cast<int>(row);
    for (int u = 0; u < c.width; ++u) {
      const int64_t i = static_cast<int64_t>(v) * c.width + u;
      const Float3 serial = cuda::ShadeRealtimePixel(f, u, v);
      const Float3 split = cuda::ShadeRealtimeHit(f, u, v, cuda::PrimaryRay(c, u, v), hits[i], true,
                                                  LaneSplitRefiner{&row_refined[v]});
      if (!(serial.x == split.x && serial.y == split.y && serial.z == split.z)) ++row_differ[v];
    }
  });
  int refined = 0, differ = 0;
  for (int v = 0; v < c.height; ++v) refined += row_refined[v], differ += row_differ[v];
  std::printf("%s 160x120: %d pixel-lights refined, %d pixels differ\n", GetParam().c_str(),
              refined, differ);
  EXPECT_GT(refined, 0);
  EXPECT_EQ(differ, 0);
}

INSTANTIATE_TEST_SUITE_P(Bundled, PenumbraLaneSplit,
                         ::testing::Values("default.yaml", "house.yaml"));

}  // namespace
}  // namespace penumbra
