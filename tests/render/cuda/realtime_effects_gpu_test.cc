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
// time. the media volumes the device builds itself (the world light volume and the fog froxels;
// the grids' light volumes and froxels) against the same volumes
// built on the host and uploaded (RealtimeFrameData::set_device_media(false)): rgb PSNR >= 50
// dB, depth equal, two device-built renders bit-identical; the grids' volumes themselves within
// stated tolerances of the host's. the particle streaks splatted on the device
// against the host splat of before (RealtimeFrameData::set_device_streaks(false)): the same
// streak pixels and t, rgb within stated tolerances. without a device every test prints
// "skipped: no CUDA device".

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
#include "penumbra/render/cuda/bvh_scene.h"
#include "penumbra/render/cuda/cuda_realtime.h"
#include "penumbra/render/cuda/cuda_renderer.h"
#include "penumbra/render/cuda/realtime_frame.h"
#include "penumbra/render/particle_math.h"
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

// the realtime particle streaks splatted and shaded on the device (the default:
// StreakSplatKernel, StreakShadeKernel) against the host splat of before in the same renderer
// (RealtimeFrameData::set_device_streaks(false): the CPU's ParticleStreaks splat and shading,
// their pixels uploaded), rain and snow (the rover's camera) and fire (sparks through the fire's
// grid media) at 1 s, 640x480. the splat's rays, projection and capsule test round every
// product and sum on their own (MulRn, AddRn), so the device's per-pixel keys give exactly the
// host's streak pixels, t and coverage (checked). the shading may still fuse multiply-adds on
// the device (the lights, the sky volume, rain's radiance computed there), so a streak's
// radiance may differ in its last bits: rgb PSNR >= 60 dB, at most 0.1 % of the pixels differ
// and at most 0.05 % by more than 3 codes (on an H200 at 14:45 UTC, before the snow's hit point
// and normal were rounded as the CPU's too: rain and fire 0 pixels, snow 147 pixels, at most
// 80 codes, 65.1 dB); depth equal; two device renders bit-identical; the device frame without
// the particles differs from the host splat's on more than 10 times as many pixels (the check
// can fail).
TEST(RealtimeEffectsGpuFrames, DeviceSplatMatchesTheHostSplat) {
  if (!ProbeCudaDevice().available) GTEST_SKIP() << "skipped: no CUDA device";
  for (const char* file : {"effects/rain.yaml", "effects/snow.yaml", "effects/fire.yaml"}) {
    SCOPED_TRACE(file);
    const auto [session, snap, view, fx] = realtime_parity::LoadFrameAt(file, 1.0, 640, 480);
    const SceneDescription& scene = session->scene();
    ASSERT_TRUE(fx && !fx->particles.empty());
    const std::unique_ptr<Renderer> gpu = EffectsBackend(scene, RenderSettings::Backend::kCuda);
    auto* g = dynamic_cast<cuda::CudaRenderer*>(gpu.get());
    ASSERT_NE(g, nullptr);
    RenderedFrame dev, again, host, bare;
    gpu->Render(snap, fx.get(), view, &dev);
    cuda::RealtimeFrameData& data = g->realtime_frame();
    EXPECT_TRUE(data.device_streaks());
    EXPECT_TRUE(data.streaks().empty());
    const cuda::PathStreaks list = data.splat_streaks().View();
    std::vector<float> alpha(list.num);
    for (int k = 0; k < list.num; ++k) alpha[k] = list.streaks[k].alpha;
    std::vector<unsigned long long> keys;
    ASSERT_TRUE(g->device_realtime().DownloadStreakKeys(&keys));
    gpu->Render(snap, fx.get(), view, &again);
    data.set_device_streaks(false);
    gpu->Render(snap, fx.get(), view, &host);
    const std::vector<cuda::StreakPixel> host_pixels = data.streaks();
    data.set_device_streaks(true);
    EffectsFrame no_particles = *fx;
    no_particles.particles.clear();
    gpu->Render(snap, &no_particles, view, &bare);
    // the device's keys against the host splat's pixels: the same pixels, t and coverage
    size_t keyed = 0, same = 0;
    for (unsigned long long key : keys) keyed += key != kNoStreakKey ? 1 : 0;
    for (const cuda::StreakPixel& s : host_pixels) {
      const unsigned long long key = keys[s.pixel];
      if (key == kNoStreakKey) continue;
      const float t = StreakKeyT(key);
      same += std::memcmp(&t, &s.t, sizeof(float)) == 0 && alpha[StreakKeyIndex(key)] == s.alpha
                  ? 1
                  : 0;
    }
    int64_t differ = 0, worst = 0, differ_bare = 0, differ_more = 0;
    for (size_t i = 0; i < dev.rgb.data.size(); i += 3) {
      int d = 0, d_bare = 0;
      for (int k = 0; k < 3; ++k) {
        d = std::max(d, std::abs(static_cast<int>(dev.rgb.data[i + k]) - host.rgb.data[i + k]));
        d_bare = std::max(d_bare,
                          std::abs(static_cast<int>(bare.rgb.data[i + k]) - host.rgb.data[i + k]));
      }
      differ += d > 0 ? 1 : 0;
      differ_more += d > 3 ? 1 : 0;
      differ_bare += d_bare > 0 ? 1 : 0;
      worst = std::max<int64_t>(worst, d);
    }
    const double psnr = realtime_parity::Psnr(host.rgb, dev.rgb);
    std::printf(
        "%s 640x480: %d streaks, %zu streak pixels (host splat), %zu keyed by the device splat, "
        "%zu with the host's t and coverage; device splat against the host splat: rgb PSNR %.2f "
        "dB, %lld pixels differ (at most %lld codes), ev100 %.4f / %.4f; without the particles "
        "%.2f dB, %lld pixels differ\n",
        file, list.num, host_pixels.size(), keyed, same, psnr, static_cast<long long>(differ),
        static_cast<long long>(worst), dev.ev100, host.ev100,
        realtime_parity::Psnr(host.rgb, bare.rgb), static_cast<long long>(differ_bare));
    EXPECT_GT(list.num, 0);
    EXPECT_GT(host_pixels.size(), 0u);
    EXPECT_EQ(keyed, host_pixels.size());
    EXPECT_EQ(same, host_pixels.size());
    EXPECT_GE(psnr, 60.0);
    EXPECT_LE(static_cast<double>(differ), 0.001 * static_cast<double>(keys.size()));
    // since the snow's hit point and normal round as the CPU's (043891f) no pixel differs by
    // more than 3 codes (H100, 15:42 UTC: 0 pixels differ in rain, snow and fire)
    EXPECT_EQ(differ_more, 0);
    EXPECT_EQ(host.depth_m.data, dev.depth_m.data);
    EXPECT_EQ(dev.rgb.data, again.rgb.data);
    EXPECT_EQ(dev.radiance.data, again.radiance.data);
    EXPECT_GT(differ_bare, 10 * std::max<int64_t>(differ, 1));
  }
}

// the late streaks (CudaRenderer culls the drops while the GPU traces and shades, then uploads
// the streaks and queues the splat): rain, snow and fire (sparks through grid media) at 1 s,
// 640x480, with the still camera, and rain and snow with a rolling shutter
// (realtime_parity::AddRollingShutter; it turns the fire's sparks out of view): the host made
// them while the GPU worked, the splat keyed pixels, two renders give the same bits, and the
// frame without its particles differs (the check can fail). the rolling shutter's device splat
// against the host splat (set_device_streaks(false)): exactly the host's streak pixels, t and
// coverage, and the rgb within DeviceSplatMatchesTheHostSplat's bounds (PSNR >= 60 dB, at most 0.1
// % of pixels differ).
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
      // the rolling shutter's device splat against the host splat
      cuda::RealtimeFrameData& data = g->realtime_frame();
      data.set_device_streaks(false);
      RenderedFrame host;
      gpu->Render(snap, fx.get(), view, &host);
      const std::vector<cuda::StreakPixel> host_pixels = data.streaks();
      data.set_device_streaks(true);
      gpu->Render(snap, fx.get(), view, &again);
      const cuda::PathStreaks list = data.splat_streaks().View();
      size_t same = 0;
      for (const cuda::StreakPixel& s : host_pixels) {
        const unsigned long long key = late_keys[s.pixel];
        if (key == kNoStreakKey) continue;
        const float t = StreakKeyT(key);
        same += std::memcmp(&t, &s.t, sizeof(float)) == 0 &&
                        list.streaks[StreakKeyIndex(key)].alpha == s.alpha
                    ? 1
                    : 0;
      }
      int64_t differ = 0;
      for (size_t i = 0; i < late.rgb.data.size(); i += 3)
        differ += std::memcmp(&late.rgb.data[i], &host.rgb.data[i], 3) != 0 ? 1 : 0;
      const double psnr = realtime_parity::Psnr(host.rgb, late.rgb);
      std::printf(
          "%s 640x480, rolling shutter: %zu streak pixels (host splat), %zu keyed by the device "
          "splat, %zu with the host's t and coverage; rgb PSNR against the host splat %.2f dB, "
          "%lld pixels differ\n",
          file, host_pixels.size(), keyed, same, psnr, static_cast<long long>(differ));
      EXPECT_GT(host_pixels.size(), 0u);
      EXPECT_EQ(keyed, host_pixels.size());
      EXPECT_EQ(same, host_pixels.size());
      EXPECT_GE(psnr, 60.0);
      EXPECT_LE(static_cast<double>(differ), 0.001 * static_cast<double>(late_keys.size()));
      EXPECT_EQ(again.radiance.data, late.radiance.data);
    }
  }
}

TEST(RealtimeEffectsGpuFrames, DeviceBuiltMediaVolumesMatchTheHostBuilt) {
  if (!ProbeCudaDevice().available) GTEST_SKIP() << "skipped: no CUDA device";
  for (const char* file :
       {"effects/fog.yaml", "effects/height_fog.yaml", "effects/smoke_plume.yaml",
        "effects/fire.yaml", "effects/vdb_smoke.yaml", "effects/adversity_major.yaml"}) {
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
    const double psnr = realtime_parity::Psnr(host.rgb, dev.rgb);
    std::printf("%s 640x480: device-built media volumes against host-built: rgb PSNR %.2f dB\n",
                file, psnr);
    EXPECT_GE(psnr, 50.0) << file;
    EXPECT_EQ(host.depth_m.data, dev.depth_m.data) << file;
    EXPECT_EQ(dev.rgb.data, again.rgb.data) << file;
    EXPECT_EQ(dev.radiance.data, again.radiance.data) << file;
  }
}

// the grids' light volumes and froxels the device built (MediaGridLightKernel,
// MediaGridFroxelKernel; DownloadGridVolumes) against RealtimeMedia::Build's on the host for the
// same frame (set_device_media(false)), 640x480: the light volumes' transmittances within 5e-5
// (the march's arithmetic: the device contracts products and sums into fused multiply-adds and
// has its own expf; on an H100 2.1e-5 at most, fire), the froxels' records within 1e-4 of the
// largest in-scatter (measured 3e-6) and 1e-4 in transmittance (2.2e-6), and within 1e-3 but
// for at most 0.5 % of them (a shadow ray that grazes an edge may change its verdict: none did),
// the froxel columns' spans within 1e-4 m + 1e-5 t (the column rays are PrimaryRay's there,
// Camera::GenerateRay's here); a second render's volumes are the same bits.
TEST(RealtimeEffectsGpuFrames, DeviceBuiltGridVolumesMatchTheHostBuild) {
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
    data.set_device_media(false);
    ThreadPool pool(2);
    data.Prepare(snap, view, &pool, fx.get());
    cuda::BvhScene bvh(scene);
    bvh.Update(snap);
    const RealtimeMediaView hm = data.View(bvh.view(), nullptr).media;
    data.set_device_media(true);
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
