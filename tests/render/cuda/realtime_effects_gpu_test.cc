// the lighting effects, particles and media on the GPU (ctest label `gpu`; issue 35 item 5): the
// frames of effects/blackout.yaml (in its power cut at 4 s), effects/flashlight.yaml,
// effects/sun.yaml, effects/rain.yaml, effects/snow.yaml, the homogeneous media of
// effects/fog.yaml, effects/height_fog.yaml and effects/dust.yaml, the grids of
// effects/smoke_plume.yaml, effects/fire.yaml and effects/vdb_smoke.yaml and
// effects/adversity_major.yaml (fog, haze, smoke, rain seen through them) render on the GPU (no
// frame goes to the CPU renderer) at 640x480 with rgb PSNR >= 40 dB and depth within 1 mm on >=
// 99.9 % of pixels against the CPU backend under the same EffectsFrame, two GPU renders
// bit-identical; one renderer alternating the sun world's clear frame and its effects frame (the
// sky rebuilt, the sky volume relit, the device sky uploaded again) gives each frame's bits every
// time. the media volumes the device builds itself (the world light volume and the fog froxels,
// branch gpu15) against the same volumes built on the host and uploaded
// (RealtimeFrameData::set_device_media(false)): rgb PSNR >= 50 dB, depth equal, two
// device-built renders bit-identical. without a device every test prints "skipped: no CUDA
// device".

#include <gtest/gtest.h>

#include <cstdio>
#include <memory>
#include <string>

#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/render/cuda/cuda_renderer.h"
#include "penumbra/render/cuda/realtime_frame.h"
#include "realtime_parity.h"

namespace penumbra {
namespace {

std::unique_ptr<Renderer> EffectsBackend(const SceneDescription& scene, RenderSettings::Backend b) {
  RenderSettings settings;
  settings.backend = b;
  return MakeRenderer(scene, settings);
}

struct GpuEffectsWorld {
  const char* file;
  double t_sec;
};

class RealtimeEffectsGpu : public ::testing::TestWithParam<GpuEffectsWorld> {};

TEST_P(RealtimeEffectsGpu, MatchesCpuBackendAndRepeatsBitForBit) {
  if (!ProbeCudaDevice().available) GTEST_SKIP() << "skipped: no CUDA device";
  const GpuEffectsWorld& w = GetParam();
  const auto [session, snap, view, fx] = realtime_parity::LoadFrameAt(w.file, w.t_sec, 640, 480);
  const SceneDescription& scene = session->scene();
  ASSERT_TRUE(fx && !fx->empty()) << w.file;
  const std::unique_ptr<Renderer> cpu = EffectsBackend(scene, RenderSettings::Backend::kEmbree);
  const std::unique_ptr<Renderer> gpu = EffectsBackend(scene, RenderSettings::Backend::kCuda);
  auto* g = dynamic_cast<cuda::CudaRenderer*>(gpu.get());
  ASSERT_NE(g, nullptr);
  RenderedFrame want, got, again;
  cpu->Render(snap, fx.get(), view, &want);
  gpu->Render(snap, fx.get(), view, &got);
  gpu->Render(snap, fx.get(), view, &again);
  EXPECT_EQ(g->gpu_frames(), 2) << w.file;
  EXPECT_EQ(g->cpu_frames(), 0) << w.file;
  const double psnr = realtime_parity::Psnr(want.rgb, got.rgb);
  const double depth_bad = realtime_parity::DepthMismatch(want.depth_m, got.depth_m);
  std::printf(
      "%s at %.1f s 640x480 rgb+depth with effects: PSNR %.2f dB (ev100 cpu %.4f gpu %.4f), "
      "depth > 1 mm on %.4f %% of pixels\n",
      w.file, w.t_sec, psnr, want.ev100, got.ev100, 100 * depth_bad);
  EXPECT_GE(psnr, 40.0) << w.file;
  EXPECT_LE(depth_bad, 0.001) << w.file;
  EXPECT_EQ(got.rgb.data, again.rgb.data) << w.file;
  EXPECT_EQ(got.radiance.data, again.radiance.data) << w.file;
  EXPECT_EQ(got.depth_m.data, again.depth_m.data) << w.file;
}

INSTANTIATE_TEST_SUITE_P(Bundled, RealtimeEffectsGpu,
                         ::testing::Values(GpuEffectsWorld{"effects/blackout.yaml", 4.0},
                                           GpuEffectsWorld{"effects/flashlight.yaml", 1.0},
                                           GpuEffectsWorld{"effects/sun.yaml", 1.0},
                                           GpuEffectsWorld{"effects/rain.yaml", 1.0},
                                           GpuEffectsWorld{"effects/snow.yaml", 1.0},
                                           GpuEffectsWorld{"effects/fog.yaml", 1.0},
                                           GpuEffectsWorld{"effects/height_fog.yaml", 1.0},
                                           GpuEffectsWorld{"effects/dust.yaml", 1.0},
                                           GpuEffectsWorld{"effects/smoke_plume.yaml", 1.0},
                                           GpuEffectsWorld{"effects/fire.yaml", 1.0},
                                           GpuEffectsWorld{"effects/vdb_smoke.yaml", 1.0},
                                           GpuEffectsWorld{"effects/adversity_major.yaml", 1.0}));

TEST(RealtimeEffectsGpuFrames, DeviceBuiltMediaVolumesMatchTheHostBuilt) {
  if (!ProbeCudaDevice().available) GTEST_SKIP() << "skipped: no CUDA device";
  for (const char* file : {"effects/fog.yaml", "effects/height_fog.yaml",
                           "effects/smoke_plume.yaml", "effects/adversity_major.yaml"}) {
    const auto [session, snap, view, fx] = realtime_parity::LoadFrameAt(file, 1.0, 640, 480);
    const SceneDescription& scene = session->scene();
    ASSERT_TRUE(fx && !fx->empty()) << file;
    const std::unique_ptr<Renderer> gpu = EffectsBackend(scene, RenderSettings::Backend::kCuda);
    auto* g = dynamic_cast<cuda::CudaRenderer*>(gpu.get());
    ASSERT_NE(g, nullptr);
    RenderedFrame dev, again, host;
    gpu->Render(snap, fx.get(), view, &dev);
    cuda::RealtimeFrameData& data = g->realtime_frame();
    EXPECT_TRUE(data.device_media()) << file;
    gpu->Render(snap, fx.get(), view, &again);
    data.set_device_media(false);
    gpu->Render(snap, fx.get(), view, &host);
    EXPECT_EQ(g->cpu_frames(), 0) << file;
    const double psnr = realtime_parity::Psnr(host.rgb, dev.rgb);
    std::printf("%s 640x480: device-built media volumes against host-built: rgb PSNR %.2f dB\n",
                file, psnr);
    EXPECT_GE(psnr, 50.0) << file;
    EXPECT_EQ(host.depth_m.data, dev.depth_m.data) << file;
    EXPECT_EQ(dev.rgb.data, again.rgb.data) << file;
    EXPECT_EQ(dev.radiance.data, again.radiance.data) << file;
  }
}

TEST(RealtimeEffectsGpuFrames, SkyChangesUploadTheSkyAgain) {
  if (!ProbeCudaDevice().available) GTEST_SKIP() << "skipped: no CUDA device";
  const auto [session, snap, view, fx] =
      realtime_parity::LoadFrameAt("effects/sun.yaml", 1.0, 160, 120);
  const SceneDescription& scene = session->scene();
  ASSERT_TRUE(fx && fx->sun_direction_W.has_value());
  const std::unique_ptr<Renderer> gpu = EffectsBackend(scene, RenderSettings::Backend::kCuda);
  RenderedFrame clear, effects, clear_again, effects_again;
  gpu->Render(snap, nullptr, view, &clear);
  gpu->Render(snap, fx.get(), view, &effects);
  gpu->Render(snap, nullptr, view, &clear_again);
  gpu->Render(snap, fx.get(), view, &effects_again);
  EXPECT_NE(clear.radiance.data, effects.radiance.data);
  EXPECT_EQ(clear.radiance.data, clear_again.radiance.data);
  EXPECT_EQ(effects.radiance.data, effects_again.radiance.data);
  // a fresh renderer's effects frame: the same bits (nothing carried over from earlier frames)
  const std::unique_ptr<Renderer> fresh = EffectsBackend(scene, RenderSettings::Backend::kCuda);
  RenderedFrame first;
  fresh->Render(snap, fx.get(), view, &first);
  EXPECT_EQ(first.radiance.data, effects.radiance.data);
  EXPECT_EQ(first.rgb.data, effects.rgb.data);
}

}  // namespace
}  // namespace penumbra
