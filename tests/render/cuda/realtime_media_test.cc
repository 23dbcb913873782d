// media (fog, haze, dust; smoke, fire and VDB grids) on the CUDA backend's
// realtime rgb path, run on the CPU (RenderRealtimeOnHost: the PB_HOST_DEVICE functions the
// kernels run) against the CPU backend rendering the same EffectsFrame: the frames of
// effects/fog.yaml, height_fog.yaml, dust.yaml, smoke_plume.yaml, fire.yaml, vdb_smoke.yaml and
// adversity_major.yaml (fog, haze, smoke and rain: particles seen through media) at 1 s (first
// camera, 160x120) give rgb PSNR >= 40 dB, depth within 1 mm on >= 99.9 % of pixels and the
// same bits twice; the same path without the media (their light transmittances and view pass)
// is far from the CPU's image.
// the media's layouts are built by RealtimeFrameData::PrepareMedia (the CPU's RealtimeMedia over
// the host BVH's RayQuery), their volumes (the world light volume, the fog froxels, the grids'
// light volumes and froxels) by the kernels' functions on the host (BuildMediaVolumesOnHost).
// PENUMBRA_PARITY_SIZE=WxH changes the bundled worlds' 160x120 (e.g. 640x480, or an odd size whose
// last quads are cut by the image's edge). no GPU needed.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>

#include "host_path.h"
#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/render/cuda/cuda_renderer.h"
#include "penumbra/render/cuda/realtime_host.h"
#include "penumbra/render/frame/bvh_ray_query.h"
#include "penumbra/render/frame/bvh_scene.h"
#include "realtime_parity.h"

namespace penumbra {
namespace {

using host_path::HostPath;

// the image size of the bundled worlds' comparison: PENUMBRA_PARITY_SIZE=WxH, else 160x120.
void ParitySize(int* w, int* h) {
  *w = 160, *h = 120;
  const char* e = std::getenv("PENUMBRA_PARITY_SIZE");
  int ew = 0, eh = 0;
  if (e != nullptr && std::sscanf(e, "%dx%d", &ew, &eh) == 2 && ew > 0 && eh > 0 && ew <= 4096 &&
      eh <= 4096)
    *w = ew, *h = eh;
}

class RealtimeHostPathMedia : public ::testing::TestWithParam<const char*> {};

TEST_P(RealtimeHostPathMedia, MatchesCpuBackend) {
  const char* file = GetParam();
  int w, h;
  ParitySize(&w, &h);
  const auto [session, snap, view, fx] = realtime_parity::LoadFrameAt(file, 1.0, w, h);
  const SceneDescription& scene = session->scene();
  ASSERT_TRUE(fx && (!fx->homogeneous_media.empty() || !fx->grid_media.empty())) << file;
  RenderSettings settings;
  settings.backend = RenderSettings::Backend::kEmbree;
  const std::unique_ptr<Renderer> cpu = MakeRenderer(scene, settings);
  RenderedFrame want;
  cpu->Render(snap, fx.get(), view, &want);
  bool has_media = false, again_media = false, bare_media = true;
  HostPath host(scene, snap);
  const RenderedFrame got = host.Render(view, fx.get(), &has_media);
  // the same frame without its media (what the media's terms bring), then the frame again
  EffectsFrame bare = *fx;
  bare.homogeneous_media.clear();
  bare.grid_media.clear();
  const RenderedFrame without = host.Render(view, &bare, &bare_media);
  const RenderedFrame again = host.Render(view, fx.get(), &again_media);
  const double psnr = realtime_parity::Psnr(want.rgb, got.rgb);
  const double bare_psnr = realtime_parity::Psnr(want.rgb, without.rgb);
  const double depth_bad = realtime_parity::DepthMismatch(want.depth_m, got.depth_m);
  std::printf(
      "%s at 1 s %dx%d (%zu homogeneous media, %zu grids, %zu particle sets): rgb PSNR %.2f dB "
      "(without the media %.2f dB), ev100 cpu %.4f host-gpu-path %.4f, depth > 1 mm on %.4f %% "
      "of pixels\n",
      file, w, h, fx->homogeneous_media.size(), fx->grid_media.size(), fx->particles.size(), psnr,
      bare_psnr, want.ev100, got.ev100, 100 * depth_bad);
  EXPECT_TRUE(has_media) << file;
  EXPECT_FALSE(bare_media) << file;
  EXPECT_GE(psnr, 40.0) << file;
  EXPECT_LE(bare_psnr, psnr - 10) << file;
  EXPECT_LE(depth_bad, 0.001) << file;
  EXPECT_EQ(got.rgb.data, again.rgb.data) << file;
  EXPECT_EQ(got.radiance.data, again.radiance.data) << file;
  EXPECT_EQ(got.depth_m.data, again.depth_m.data) << file;
}

INSTANTIATE_TEST_SUITE_P(Bundled, RealtimeHostPathMedia,
                         ::testing::Values("effects/fog.yaml", "effects/height_fog.yaml",
                                           "effects/dust.yaml", "effects/smoke_plume.yaml",
                                           "effects/fire.yaml", "effects/vdb_smoke.yaml",
                                           "effects/adversity_major.yaml"));

// the media's shadow rays through another RayQuery posed for the frame (as CudaRenderer passes
// its CudaRayQuery) give the frame data's own BvhRayQuery's image: the same traversal, so the same
// bits; and the surface evaluated again in the shading pass (ShadeRealtimePixel) gives the stored
// terms' bits with media too.
TEST(RealtimeHostPathMediaFrames, MediaRaysAndShadingPathsGiveTheSameBits) {
  const auto [session, snap, view, fx] =
      realtime_parity::LoadFrameAt("effects/height_fog.yaml", 1.0, 96, 72);
  const SceneDescription& scene = session->scene();
  ASSERT_TRUE(fx && !fx->homogeneous_media.empty());
  cuda::BvhRayQuery rays(scene);
  rays.Update(snap);
  bool own_media = false, given_media = false;
  HostPath host(scene, snap);
  const RenderedFrame own = host.Render(view, fx.get(), &own_media);
  const RenderedFrame given = host.Render(view, fx.get(), &given_media, &rays);
  EXPECT_TRUE(own_media && given_media);
  EXPECT_EQ(own.radiance.data, given.radiance.data);
  cuda::BvhScene bvh(scene);
  bvh.Update(snap);
  cuda::RealtimeFrameData data(scene, RenderSettings());
  ThreadPool pool(0);
  data.Prepare(snap, view, &pool, fx.get());
  RenderedFrame stored, evaluated;
  cuda::RenderRealtimeOnHost(data, bvh, &pool, &stored, /*stored_surface=*/true);
  cuda::RenderRealtimeOnHost(data, bvh, &pool, &evaluated, /*stored_surface=*/false);
  EXPECT_EQ(stored.radiance.data, evaluated.radiance.data);
  EXPECT_EQ(stored.radiance.data, own.radiance.data);
}

// the world light volume and the fog froxels that PrepareMedia leaves to the frame
// (View's media_build), built as the device builds them (BuildMediaVolumesOnHost:
// MediaLightVolumeCell with its shadow rays traced in the cell, MediaFogColumn): the frame
// says which it left (their host arrays null), the build fills them (transmittances in [0, 1],
// some fog in-scatter), twice to the bit; fog (visibility rays), smoke (grids only: their own
// volumes are the next test's) and the major preset (both).
TEST(RealtimeHostPathMediaFrames, FrameBuiltVolumes) {
  for (const char* file :
       {"effects/fog.yaml", "effects/smoke_plume.yaml", "effects/adversity_major.yaml"}) {
    const auto [session, snap, view, fx] = realtime_parity::LoadFrameAt(file, 1.0, 160, 120);
    const SceneDescription& scene = session->scene();
    ASSERT_TRUE(fx && (!fx->homogeneous_media.empty() || !fx->grid_media.empty())) << file;
    cuda::BvhScene bvh(scene);
    bvh.Update(snap);
    ThreadPool pool(0);
    cuda::RealtimeFrameData data(scene, RenderSettings());
    data.Prepare(snap, view, &pool, fx.get());
    cuda::RealtimeFrameView dev = data.View(bvh.view(), nullptr);
    if (!fx->homogeneous_media.empty()) {
      EXPECT_EQ(dev.media_build.light_volume, 1) << file;
    }
    EXPECT_EQ(dev.media.light_trans, nullptr) << file;
    EXPECT_EQ(dev.media.fog_S, nullptr) << file;
    cuda::MediaVolumeArrays built, again;
    cuda::BuildMediaVolumesOnHost(&dev, &pool, &built);
    cuda::RealtimeFrameView dev2 = data.View(bvh.view(), nullptr);
    cuda::BuildMediaVolumesOnHost(&dev2, &pool, &again);
    EXPECT_EQ(built.trans, again.trans) << file;
    ASSERT_EQ(built.fog.size(), again.fog.size()) << file;
    EXPECT_EQ(std::memcmp(built.fog.data(), again.fog.data(), sizeof(Rgb4) * built.fog.size()), 0)
        << file;
    EXPECT_EQ(built.trans.empty(), dev.media_build.light_volume == 0) << file;
    for (float t : built.trans) {
      ASSERT_GE(t, 0.0f) << file;
      ASSERT_LE(t, 1.0f) << file;
    }
    float peak = 0;
    for (const Rgb4& r : built.fog) peak = std::max({peak, r.x, r.y, r.z});
    std::printf("%s: light volume %zu values, fog froxels %zu records, in-scatter peak %.3g\n",
                file, built.trans.size(), built.fog.size(), peak);
    if (dev.media_build.fog != 0) {
      EXPECT_GT(peak, 0.0f) << file;
    }
  }
}

// the grids' light volumes and froxels that PrepareMedia leaves to the frame, built as the
// device builds them (BuildMediaVolumesOnHost: MediaGridLightCell with its shadow rays traced in
// the cell, MediaGridFroxelColumn): the frame says it left them (their host arrays null), the
// build fills the light volumes (transmittances in [0, 1]) and froxel columns (some meet a grid,
// some in-scatter), twice to the bit. smoke, fire (emissive), VDB and the major preset (a smoke
// grid under fog).
TEST(RealtimeHostPathMediaFrames, FrameBuiltGridVolumes) {
  for (const char* file : {"effects/smoke_plume.yaml", "effects/fire.yaml",
                           "effects/vdb_smoke.yaml", "effects/adversity_major.yaml"}) {
    const auto [session, snap, view, fx] = realtime_parity::LoadFrameAt(file, 1.0, 160, 120);
    const SceneDescription& scene = session->scene();
    ASSERT_TRUE(fx && !fx->grid_media.empty()) << file;
    cuda::BvhScene bvh(scene);
    bvh.Update(snap);
    ThreadPool pool(0);
    cuda::RealtimeFrameData data(scene, RenderSettings());
    data.Prepare(snap, view, &pool, fx.get());
    cuda::RealtimeFrameView dev = data.View(bvh.view(), nullptr);
    EXPECT_EQ(dev.media_build.grids, 1) << file;
    EXPECT_NE(dev.media_build.grid_media, nullptr) << file;
    EXPECT_EQ(dev.media.grid_light_T, nullptr) << file;
    EXPECT_EQ(dev.media.grid_records, nullptr) << file;
    const size_t columns = static_cast<size_t>(dev.media.grid_nx) * dev.media.grid_ny;
    ASSERT_GT(columns, 0u) << file;
    cuda::MediaVolumeArrays built, again;
    cuda::BuildMediaVolumesOnHost(&dev, &pool, &built);
    cuda::RealtimeFrameView dev2 = data.View(bvh.view(), nullptr);
    cuda::BuildMediaVolumesOnHost(&dev2, &pool, &again);
    ASSERT_FALSE(built.grids.T.empty()) << file;
    EXPECT_EQ(built.grids.T, again.grids.T) << file;
    EXPECT_EQ(built.grids.t0, again.grids.t0) << file;
    EXPECT_EQ(built.grids.t1, again.grids.t1) << file;
    ASSERT_EQ(built.grids.records.size(), columns * (kFroxelSlices + 1)) << file;
    ASSERT_EQ(again.grids.records.size(), built.grids.records.size()) << file;
    EXPECT_EQ(std::memcmp(built.grids.records.data(), again.grids.records.data(),
                          sizeof(GridFroxelRecord<Rgb4>) * built.grids.records.size()),
              0)
        << file;
    for (float t : built.grids.T) {
      ASSERT_GE(t, 0.0f) << file;
      ASSERT_LE(t, 1.0f) << file;
    }
    int met = 0;
    for (size_t c = 0; c < columns; ++c) met += built.grids.t0[c] < built.grids.t1[c] ? 1 : 0;
    float peak = 0;
    for (const GridFroxelRecord<Rgb4>& r : built.grids.records)
      peak = std::max({peak, r.S.x, r.S.y, r.S.z});
    std::printf(
        "%s: grid light volumes %zu values, grid froxels %zu columns (%d meet a grid), "
        "in-scatter peak %.3g\n",
        file, built.grids.T.size(), columns, met, peak);
    EXPECT_GT(met, 0) << file;
    EXPECT_GT(peak, 0.0f) << file;
  }
}

}  // namespace
}  // namespace penumbra
