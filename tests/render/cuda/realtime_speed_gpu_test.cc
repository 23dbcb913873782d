// the realtime kernels' speed-ups (cuda_realtime.h, RealtimeKernelOptions) change no pixel
// (ctest label `gpu`): on the default room (lamps) and the house (the sun through windows) at
// 640x480, the radiance and depth with every speed-up are the same bits as with each one turned
// off (the primary hit traced again by the shading kernel, the surface evaluated again by it,
// one thread per row sum, pageable copies, each pixel tracing its own penumbra rays, the
// kernels' registers uncapped, the radiance copied back in 1 or 5 bands); the rgb too, except that
// the row sums' order can move the exposure's last bits (then the EV100 agrees to 1e-9). without a
// device every test prints "skipped: no CUDA device".

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/render/cuda/cuda_renderer.h"
#include "realtime_parity.h"

namespace penumbra {
namespace {

class RealtimeSpeedUps : public ::testing::TestWithParam<std::string> {};

TEST_P(RealtimeSpeedUps, ChangeNoPixel) {
  if (!ProbeCudaDevice().available) GTEST_SKIP() << "skipped: no CUDA device";
  const std::unique_ptr<Session> session = realtime_parity::LoadSimulated(GetParam());
  const SceneDescription& scene = session->scene();
  const WorldSnapshot snap = session->sim().Snapshot();
  const CameraView view = realtime_parity::RgbDepthView(scene, snap, 640, 480);
  RenderSettings gpu_settings;
  gpu_settings.backend = RenderSettings::Backend::kCuda;
  const std::unique_ptr<Renderer> gpu = MakeRenderer(scene, gpu_settings);
  auto* g = dynamic_cast<cuda::CudaRenderer*>(gpu.get());
  ASSERT_NE(g, nullptr);
  const cuda::RealtimeKernelOptions fast = g->device_realtime().options();
  EXPECT_TRUE(fast.reuse_hit && fast.rows_per_warp && fast.pinned);
  RenderedFrame want;
  gpu->Render(snap, view, &want);
  struct Variant {
    const char* name;
    cuda::RealtimeKernelOptions o;
  };
  std::vector<Variant> variants;
  const char* names[] = {"reuse_hit off",
                         "rows_per_warp off",
                         "pinned off",
                         "all off",
                         "min_blocks 1",
                         "min_blocks 6",
                         "warp_penumbra off",
                         "reuse_surface off",
                         "reuse_surface off, min_blocks 1",
                         "geometry_min_blocks 1",
                         "output_bands 1",
                         "output_bands 5"};
  for (int k = 0; k < 12; ++k) {
    cuda::RealtimeKernelOptions o = fast;
    if (k == 0) o.reuse_hit = false;
    if (k == 1) o.rows_per_warp = false;
    if (k == 2) o.pinned = false;
    if (k == 3) {
      o.reuse_hit = o.reuse_surface = o.rows_per_warp = o.pinned = o.warp_penumbra = false;
      o.min_blocks = o.geometry_min_blocks = 0;
      o.output_bands = 1;
    }
    if (k == 4 || k == 8) o.min_blocks = 1;
    if (k == 5) o.min_blocks = 6;
    if (k == 6) o.warp_penumbra = false;
    if (k == 7 || k == 8) o.reuse_surface = false;
    if (k == 9) o.geometry_min_blocks = 1;
    if (k == 10) o.output_bands = 1;
    if (k == 11) o.output_bands = 5;
    variants.push_back({names[k], o});
  }
  for (const Variant& var : variants) {
    g->device_realtime().set_options(var.o);
    RenderedFrame got;
    gpu->Render(snap, view, &got);
    const bool same_rgb = got.rgb.data == want.rgb.data;
    std::printf("%s %s: radiance %s, depth %s, rgb %s, ev100 %.12f / %.12f\n", GetParam().c_str(),
                var.name, got.radiance.data == want.radiance.data ? "same" : "DIFFERENT",
                got.depth_m.data == want.depth_m.data ? "same" : "DIFFERENT",
                same_rgb ? "same" : "different", got.ev100, want.ev100);
    EXPECT_EQ(got.radiance.data, want.radiance.data) << var.name;
    EXPECT_EQ(got.depth_m.data, want.depth_m.data) << var.name;
    EXPECT_NEAR(got.ev100, want.ev100, 1e-9) << var.name;
    if (var.o.rows_per_warp) {
      EXPECT_EQ(got.ev100, want.ev100) << var.name;
      EXPECT_TRUE(same_rgb) << var.name;
    }
  }
  g->device_realtime().set_options(fast);
}

INSTANTIATE_TEST_SUITE_P(Bundled, RealtimeSpeedUps,
                         ::testing::Values("default.yaml", "house.yaml"));

}  // namespace
}  // namespace penumbra
