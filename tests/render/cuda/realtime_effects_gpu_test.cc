// the lighting effects, particles and media on the GPU (ctest label `gpu`): the
// frames of effects/blackout.yaml (in its power cut at 4 s), effects/flashlight.yaml,
// effects/sun.yaml, effects/rain.yaml, effects/snow.yaml, the homogeneous media of
// effects/fog.yaml, effects/height_fog.yaml and effects/dust.yaml, the grids of
// effects/smoke_plume.yaml, effects/fire.yaml and effects/vdb_smoke.yaml and
// effects/adversity_major.yaml (fog, haze, smoke, rain seen through them) render on the GPU (no
// frame goes to the CPU renderer) at 640x480 with rgb PSNR >= 40 dB and depth within 1 mm on >=
// 99.9 % of pixels against the CPU backend under the same EffectsFrame, two GPU renders
// bit-identical; one renderer alternating the sun world's clear frame and its effects frame (the
// sky rebuilt, the sky volume relit, the device sky uploaded again) gives each frame's bits every
// time. the grids' light volumes and froxels the device builds against the same functions run on
// the host (BuildMediaVolumesOnHost): within stated tolerances. the particle streaks splatted on
// the device against the same splat run on the host (SplatProjection, SplatStreakRow): the same
// streak pixels, t and coverage. without a device every test prints "skipped: no CUDA device".

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "penumbra/core/thread_pool.h"
#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/render/cuda/cuda_realtime.h"
#include "penumbra/render/cuda/cuda_renderer.h"
#include "penumbra/render/cuda/realtime_host.h"
#include "penumbra/render/frame/bvh_scene.h"
#include "penumbra/render/particles/particle_math.h"
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

// the splat keys of the frame `data` was last Prepared for (its streaks downloaded,
// splat_streaks), made on the host by the device's splat functions: per pixel the nearest
// streak's key, kNoStreakKey where none.
std::vector<unsigned long long> HostSplatKeys(const cuda::RealtimeFrameData& data, int W, int H) {
  cuda::RealtimeFrameView f = data.View(cuda::SceneView(), nullptr);
  f.splat.streaks = data.splat_streaks().View();
  f.splat.count = nullptr;
  std::vector<unsigned long long> keys(static_cast<size_t>(W) * H, kNoStreakKey);
  f.splat.nearest = keys.data();
  for (int k = 0; k < f.splat.streaks.num; ++k) {
    const StreakProjection p = cuda::SplatProjection(f, f.splat.streaks.streaks[k]);
    for (int v = p.v0; v <= p.v1 && !p.empty(); ++v) cuda::SplatStreakRow(f, k, p, v);
  }
  return keys;
}

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

// the realtime particle streaks splatted and shaded on the device (StreakSplatKernel,
// StreakShadeKernel), rain and snow (the rover's camera) and fire (sparks through the fire's grid
// media) at 1 s, 640x480. the splat's rays, projection and capsule test round every product and
// sum on their own (MulRn, AddRn), so the device's per-pixel keys are exactly those of the same
// splat run on the host (HostSplatKeys: the same pixels, t and coverage); two device renders are
// bit-identical; the device frame without the particles differs (the check can fail).
TEST(RealtimeEffectsGpuFrames, DeviceSplatKeysTheHostSplatsPixels) {
  if (!ProbeCudaDevice().available) GTEST_SKIP() << "skipped: no CUDA device";
  for (const char* file : {"effects/rain.yaml", "effects/snow.yaml", "effects/fire.yaml"}) {
    SCOPED_TRACE(file);
    const auto [session, snap, view, fx] = realtime_parity::LoadFrameAt(file, 1.0, 640, 480);
    const SceneDescription& scene = session->scene();
    ASSERT_TRUE(fx && !fx->particles.empty());
    const std::unique_ptr<Renderer> gpu = EffectsBackend(scene, RenderSettings::Backend::kCuda);
    auto* g = dynamic_cast<cuda::CudaRenderer*>(gpu.get());
    ASSERT_NE(g, nullptr);
    RenderedFrame dev, again, bare;
    gpu->Render(snap, fx.get(), view, &dev);
    cuda::RealtimeFrameData& data = g->realtime_frame();
    const int num = data.splat_streaks().View().num;
    std::vector<unsigned long long> keys;
    ASSERT_TRUE(g->device_realtime().DownloadStreakKeys(&keys));
    const std::vector<unsigned long long> host_keys =
        HostSplatKeys(data, view.intrinsics.width, view.intrinsics.height);
    gpu->Render(snap, fx.get(), view, &again);
    EffectsFrame no_particles = *fx;
    no_particles.particles.clear();
    gpu->Render(snap, &no_particles, view, &bare);
    size_t keyed = 0, host_keyed = 0, differ_keys = 0;
    for (size_t i = 0; i < keys.size() && i < host_keys.size(); ++i) {
      keyed += keys[i] != kNoStreakKey ? 1 : 0;
      host_keyed += host_keys[i] != kNoStreakKey ? 1 : 0;
      differ_keys += keys[i] != host_keys[i] ? 1 : 0;
    }
    int64_t differ_bare = 0;
    for (size_t i = 0; i < dev.rgb.data.size(); i += 3)
      differ_bare += std::memcmp(&dev.rgb.data[i], &bare.rgb.data[i], 3) != 0 ? 1 : 0;
    std::printf(
        "%s 640x480: %d streaks, %zu pixels keyed by the device splat, %zu by the host's, %zu "
        "keys differ; without the particles %.2f dB, %lld pixels differ\n",
        file, num, keyed, host_keyed, differ_keys, realtime_parity::Psnr(dev.rgb, bare.rgb),
        static_cast<long long>(differ_bare));
    EXPECT_GT(num, 0);
    EXPECT_GT(keyed, 0u);
    ASSERT_EQ(keys.size(), host_keys.size());
    EXPECT_EQ(differ_keys, 0u);
    EXPECT_EQ(dev.rgb.data, again.rgb.data);
    EXPECT_EQ(dev.radiance.data, again.radiance.data);
    EXPECT_GT(differ_bare, 0);
  }
}

// the late streaks (CudaRenderer culls the drops while the GPU traces and shades, then uploads
// the streaks and queues the splat): rain, snow and fire (sparks through grid media) at 1 s,
// 640x480, with the still camera, and rain and snow with a rolling shutter
// (realtime_parity::AddRollingShutter; it turns the fire's sparks out of view): the host made
// them while the GPU worked, the splat keyed pixels, two renders give the same bits, and the
// frame without its particles differs (the check can fail). the rolling shutter's device splat
// against the same splat run on the host (HostSplatKeys): exactly its streak pixels, t and
// coverage.
TEST(RealtimeEffectsGpuFrames, LateStreaksRenderRepeatably) {
  if (!ProbeCudaDevice().available) GTEST_SKIP() << "skipped: no CUDA device";
  for (const char* file : {"effects/rain.yaml", "effects/snow.yaml", "effects/fire.yaml"}) {
    for (const bool rolling : {false, true}) {
      // (the rolling shutter turns the fire's sparks out of view: no streak pixel to compare)
      if (rolling && std::string(file) == "effects/fire.yaml") continue;
      SCOPED_TRACE(std::string(file) + (rolling ? ", rolling shutter" : ", still camera"));
      auto [session, snap, view, fx] = realtime_parity::LoadFrameAt(file, 1.0, 640, 480);
      if (rolling) realtime_parity::AddRollingShutter(&view);
      const SceneDescription& scene = session->scene();
      ASSERT_TRUE(fx && !fx->particles.empty());
      const std::unique_ptr<Renderer> gpu = EffectsBackend(scene, RenderSettings::Backend::kCuda);
      auto* g = dynamic_cast<cuda::CudaRenderer*>(gpu.get());
      ASSERT_NE(g, nullptr);
      RenderedFrame late, again, bare;
      std::vector<unsigned long long> late_keys, again_keys;
      gpu->Render(snap, fx.get(), view, &late);
      const double late_ms = g->last_late_streaks_ms();
      const int num = g->realtime_frame().splat_streaks().View().num;
      ASSERT_TRUE(g->device_realtime().DownloadStreakKeys(&late_keys));
      gpu->Render(snap, fx.get(), view, &again);
      ASSERT_TRUE(g->device_realtime().DownloadStreakKeys(&again_keys));
      EffectsFrame no_particles = *fx;
      no_particles.particles.clear();
      gpu->Render(snap, &no_particles, view, &bare);
      EXPECT_EQ(g->last_late_streaks_ms(), 0.0);
      size_t keyed = 0;
      for (unsigned long long key : late_keys) keyed += key != kNoStreakKey ? 1 : 0;
      std::printf(
          "%s 640x480%s: %d streaks, %zu keyed pixels; late streaks (%.2f ms on the host while "
          "the GPU worked), two renders the same bits %s, EV100 %.6f / %.6f; without the "
          "particles %.2f dB\n",
          file, rolling ? ", rolling shutter" : "", num, keyed, late_ms,
          late.radiance.data == again.radiance.data && late.rgb.data == again.rgb.data ? "yes"
                                                                                       : "NO",
          late.ev100, again.ev100, realtime_parity::Psnr(late.rgb, bare.rgb));
      EXPECT_GT(late_ms, 0.0);
      EXPECT_GT(keyed, 0u);
      EXPECT_EQ(late_keys, again_keys);
      EXPECT_EQ(late.rgb.data, again.rgb.data);
      EXPECT_EQ(late.radiance.data, again.radiance.data);
      EXPECT_EQ(late.depth_m.data, again.depth_m.data);
      EXPECT_EQ(std::memcmp(&late.ev100, &again.ev100, sizeof(double)), 0);
      EXPECT_NE(late.radiance.data, bare.radiance.data);
      if (!rolling || std::string(file) != "effects/rain.yaml") continue;
      // the rolling shutter's device splat against the same splat on the host (the frame data
      // of the particles' frame again)
      gpu->Render(snap, fx.get(), view, &again);
      const std::vector<unsigned long long> host_keys =
          HostSplatKeys(g->realtime_frame(), view.intrinsics.width, view.intrinsics.height);
      EXPECT_EQ(late_keys, host_keys);
    }
  }
}

// the grids' light volumes and froxels the device built (MediaGridLightKernel,
// MediaGridFroxelKernel; DownloadGridVolumes) against the same functions run on the host for the
// same frame (BuildMediaVolumesOnHost), 640x480: the light volumes' transmittances within 5e-5
// (the march's arithmetic: the device contracts products and sums into fused multiply-adds and
// has its own expf; on an H100 2.1e-5 at most, fire), the froxels' records within 1e-4 of the
// largest in-scatter (measured 3e-6) and 1e-4 in transmittance (2.2e-6), and within 1e-3 but
// for at most 0.5 % of them (a shadow ray that grazes an edge may change its verdict: none did),
// the froxel columns' spans within 1e-4 m + 1e-5 t; a second render's volumes are the same bits.
TEST(RealtimeEffectsGpuFrames, DeviceBuiltGridVolumesMatchTheHostFunctions) {
  if (!ProbeCudaDevice().available) GTEST_SKIP() << "skipped: no CUDA device";
  for (const char* file : {"effects/smoke_plume.yaml", "effects/fire.yaml",
                           "effects/vdb_smoke.yaml", "effects/adversity_major.yaml"}) {
    const auto [session, snap, view, fx] = realtime_parity::LoadFrameAt(file, 1.0, 640, 480);
    const SceneDescription& scene = session->scene();
    ASSERT_TRUE(fx && !fx->grid_media.empty()) << file;
    const std::unique_ptr<Renderer> gpu = EffectsBackend(scene, RenderSettings::Backend::kCuda);
    auto* g = dynamic_cast<cuda::CudaRenderer*>(gpu.get());
    ASSERT_NE(g, nullptr);
    RenderedFrame frame;
    gpu->Render(snap, fx.get(), view, &frame);
    cuda::GridVolumeArrays dev, again;
    ASSERT_TRUE(g->device_realtime().DownloadGridVolumes(&dev)) << file;
    gpu->Render(snap, fx.get(), view, &frame);
    ASSERT_TRUE(g->device_realtime().DownloadGridVolumes(&again)) << file;
    EXPECT_EQ(dev.T, again.T) << file;
    EXPECT_EQ(0, std::memcmp(dev.records.data(), again.records.data(),
                             sizeof(GridFroxelRecord<Rgb4>) * dev.records.size()))
        << file;
    // the host build of the same frame on the renderer's own frame data
    cuda::RealtimeFrameData& data = g->realtime_frame();
    ThreadPool pool(2);
    data.Prepare(snap, view, &pool, fx.get());
    cuda::BvhScene bvh(scene);
    bvh.Update(snap);
    cuda::RealtimeFrameView host = data.View(bvh.view(), nullptr);
    cuda::MediaVolumeArrays host_built;
    cuda::BuildMediaVolumesOnHost(&host, &pool, &host_built);
    const RealtimeMediaView& hm = host.media;
    ASSERT_GT(hm.num_grids, 0) << file;
    const GridLightPod& last = hm.grids[hm.num_grids - 1];
    const size_t values =
        last.offset + static_cast<size_t>(hm.num_grid_lights) * last.r[0] * last.r[1] * last.r[2];
    ASSERT_EQ(dev.T.size(), values) << file;
    float worst_T = 0;
    for (size_t i = 0; i < values; ++i)
      worst_T = std::max(worst_T, std::abs(dev.T[i] - hm.grid_light_T[i]));
    const size_t columns = static_cast<size_t>(hm.grid_nx) * hm.grid_ny;
    ASSERT_EQ(dev.t0.size(), columns) << file;
    int spans_off = 0, met = 0;
    for (size_t c = 0; c < columns; ++c) {
      const bool a = hm.grid_t0[c] < hm.grid_t1[c], b = dev.t0[c] < dev.t1[c];
      met += a ? 1 : 0;
      const float tol = 1e-4f + 1e-5f * hm.grid_t1[c];
      if (a != b || std::abs(hm.grid_t0[c] - dev.t0[c]) > tol ||
          std::abs(hm.grid_t1[c] - dev.t1[c]) > tol)
        ++spans_off;
    }
    const size_t records = columns * (kFroxelSlices + 1);
    ASSERT_EQ(dev.records.size(), records) << file;
    float peak = 0;
    for (size_t i = 0; i < records; ++i)
      peak =
          std::max({peak, hm.grid_records[i].S.x, hm.grid_records[i].S.y, hm.grid_records[i].S.z});
    int off = 0;
    float worst_S = 0, worst_Tr = 0;
    for (size_t i = 0; i < records; ++i) {
      const GridFroxelRecord<Rgb4>& a = hm.grid_records[i];
      const GridFroxelRecord<Rgb4>& b = dev.records[i];
      const float dS =
          std::max({std::abs(a.S.x - b.S.x), std::abs(a.S.y - b.S.y), std::abs(a.S.z - b.S.z)});
      const float dT =
          std::max({std::abs(a.T.x - b.T.x), std::abs(a.T.y - b.T.y), std::abs(a.T.z - b.T.z)});
      worst_S = std::max(worst_S, dS);
      worst_Tr = std::max(worst_Tr, dT);
      off += dS > 1e-3f * peak || dT > 1e-3f ? 1 : 0;
    }
    std::printf(
        "%s 640x480: grid light volumes %zu values, largest difference %.3g; froxels %zu "
        "columns (%d meet a grid, %d spans off), %zu records: largest in-scatter difference %.3g "
        "of peak %.3g, transmittance %.3g, %d beyond 1e-3; two device builds %s\n",
        file, values, worst_T, columns, met, spans_off, records, worst_S, peak, worst_Tr, off,
        dev.T == again.T ? "equal" : "DIFFERENT");
    EXPECT_GT(met, 0) << file;
    EXPECT_LE(worst_T, 5e-5f) << file;
    EXPECT_LE(worst_S, 1e-4f * peak) << file;
    EXPECT_LE(worst_Tr, 1e-4f) << file;
    EXPECT_LE(spans_off, static_cast<int>(columns / 200)) << file;
    EXPECT_LE(off, static_cast<int>(records / 200)) << file;
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
