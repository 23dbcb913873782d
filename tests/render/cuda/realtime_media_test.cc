// media (fog, haze, dust; smoke, fire and VDB grids) on the CUDA backend's
// realtime rgb path, run on the CPU (RenderRealtimeOnHost: the PB_HOST_DEVICE functions the
// kernels run) against the CPU backend rendering the same EffectsFrame: the frames of
// effects/fog.yaml, height_fog.yaml, dust.yaml, smoke_plume.yaml, fire.yaml, vdb_smoke.yaml and
// adversity_major.yaml (fog, haze, smoke and rain: particles seen through media) at 1 s (first
// camera, 160x120) give rgb PSNR >= 40 dB, depth within 1 mm on >= 99.9 % of pixels and the
// same bits twice; the same path without the media (their light transmittances and view pass)
// is far from the CPU's image.
// the media's volumes are built by RealtimeFrameData::PrepareMedia (the CPU's RealtimeMedia over
// the host BVH's RayQuery), the world light volume and the fog froxels by the kernels' functions
// on the host (BuildMediaVolumesOnHost), which must give the host build's light
// volume bit for bit and its fog froxels up to the column rays' rounding; the
// grids' light volumes and froxels too (bit for bit, and up to the column rays' rounding).
// PENUMBRA_PARITY_SIZE=WxH changes the bundled worlds' 160x120 (e.g. 640x480, or an odd size whose
// last quads are cut by the image's edge). no GPU needed.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

#include "host_path.h"
#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/render/cuda/bvh_ray_query.h"
#include "penumbra/render/cuda/bvh_scene.h"
#include "penumbra/render/cuda/cuda_renderer.h"
#include "penumbra/render/cuda/realtime_frame.h"
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

// the world light volume and the fog froxels built as the device builds them (RealtimeFrameData's
// device_media, BuildMediaVolumesOnHost: MediaLightVolumeCell with its shadow rays traced in the
// cell, MediaFogColumn) against RealtimeMedia::Build's on the host (set_device_media(false)):
// the light volume's transmittances bit for bit (the same functions and shadow rays), the fog
// froxels within 1e-4 of their largest value (the column rays are PrimaryRay's, not
// Camera::GenerateRay's), the two frames' rgb within 50 dB; fog (visibility rays), smoke (grids
// only: their volumes are the device's too, next test) and the major preset
// (both).
TEST(RealtimeHostPathMediaFrames, DeviceBuiltVolumesMatchTheHostBuild) {
  for (const char* file :
       {"effects/fog.yaml", "effects/smoke_plume.yaml", "effects/adversity_major.yaml"}) {
    const auto [session, snap, view, fx] = realtime_parity::LoadFrameAt(file, 1.0, 160, 120);
    const SceneDescription& scene = session->scene();
    ASSERT_TRUE(fx && (!fx->homogeneous_media.empty() || !fx->grid_media.empty())) << file;
    cuda::BvhScene bvh(scene);
    bvh.Update(snap);
    ThreadPool pool(0);
    cuda::RealtimeFrameData data(scene, RenderSettings());
    EXPECT_TRUE(data.device_media());
    data.set_device_media(false);
    data.Prepare(snap, view, &pool, fx.get());
    const cuda::RealtimeFrameView host = data.View(bvh.view(), nullptr);
    ASSERT_EQ(host.media_build.light_volume + host.media_build.fog, 0) << file;
    const CellLightsPod& v = host.media.light_volume;
    const size_t cells = static_cast<size_t>(v.r[0]) * v.r[1] * v.r[2] * v.stride;
    const std::vector<float> host_trans(host.media.light_trans,
                                        host.media.light_trans + (v.stride > 0 ? cells : 0));
    const size_t fog_n = static_cast<size_t>(host.media.fog_nx) * host.media.fog_ny;
    std::vector<Rgb4> host_fog;
    if (host.media.fog_S != nullptr)
      host_fog.assign(host.media.fog_S, host.media.fog_S + fog_n * (kFogFroxelSlices + 1));
    RenderedFrame host_frame;
    cuda::RenderRealtimeOnHost(data, bvh, &pool, &host_frame, true);

    data.set_device_media(true);
    data.Prepare(snap, view, &pool, fx.get());
    cuda::RealtimeFrameView dev = data.View(bvh.view(), nullptr);
    EXPECT_EQ(dev.media_build.light_volume, v.stride > 0 ? 1 : 0) << file;
    EXPECT_EQ(dev.media_build.fog, host.media.fog_S != nullptr ? 1 : 0) << file;
    EXPECT_EQ(dev.media.light_trans, nullptr) << file;
    EXPECT_EQ(dev.media.fog_S, nullptr) << file;
    cuda::MediaVolumeArrays built;
    cuda::BuildMediaVolumesOnHost(&dev, &pool, &built);
    EXPECT_EQ(built.trans, host_trans) << file;
    ASSERT_EQ(built.fog.size(), host_fog.size()) << file;
    float peak = 0, worst = 0;
    for (size_t i = 0; i < host_fog.size(); ++i) {
      const Rgb4& a = host_fog[i];
      const Rgb4& b = built.fog[i];
      peak = std::max({peak, a.x, a.y, a.z});
      worst = std::max({worst, std::abs(a.x - b.x), std::abs(a.y - b.y), std::abs(a.z - b.z)});
    }
    RenderedFrame dev_frame;
    cuda::RenderRealtimeOnHost(data, bvh, &pool, &dev_frame, true);
    const double psnr = realtime_parity::Psnr(host_frame.rgb, dev_frame.rgb);
    std::printf(
        "%s: light volume %zu values (%s), fog froxels %zu records, largest difference %.3g of "
        "peak %.3g; rgb PSNR device-built against host-built %.2f dB\n",
        file, host_trans.size(), built.trans == host_trans ? "equal" : "DIFFERENT", host_fog.size(),
        worst, peak, psnr);
    EXPECT_LE(worst, 1e-4f * peak) << file;
    EXPECT_GE(psnr, 50.0) << file;
    EXPECT_EQ(host_frame.depth_m.data, dev_frame.depth_m.data) << file;
  }
}

// the grids' light volumes and froxels built as the device builds them (device_media,
// BuildMediaVolumesOnHost: MediaGridLightCell with its shadow rays traced in the cell,
// MediaGridFroxelColumn) against RealtimeMedia::Build's on the host (set_device_media(false)):
// the light volumes' transmittances bit for bit (the same functions and shadow rays); the grid
// froxels' columns ([t0, t1]) and records up to the column rays' rounding (PrimaryRay's, not
// Camera::GenerateRay's: within 1e-4 m + 1e-5 t, 1e-5 of the largest in-scatter and 1e-5 in
// transmittance; measured 1.5e-7 and 4.2e-7 at most); the two frames' rgb within 50 dB, depth
// equal. smoke, fire (emissive), VDB
// and the major preset (a smoke grid under fog).
TEST(RealtimeHostPathMediaFrames, DeviceBuiltGridVolumesMatchTheHostBuild) {
  for (const char* file : {"effects/smoke_plume.yaml", "effects/fire.yaml",
                           "effects/vdb_smoke.yaml", "effects/adversity_major.yaml"}) {
    const auto [session, snap, view, fx] = realtime_parity::LoadFrameAt(file, 1.0, 160, 120);
    const SceneDescription& scene = session->scene();
    ASSERT_TRUE(fx && !fx->grid_media.empty()) << file;
    cuda::BvhScene bvh(scene);
    bvh.Update(snap);
    ThreadPool pool(0);
    cuda::RealtimeFrameData data(scene, RenderSettings());
    data.set_device_media(false);
    data.Prepare(snap, view, &pool, fx.get());
    const cuda::RealtimeFrameView host = data.View(bvh.view(), nullptr);
    ASSERT_EQ(host.media_build.grids, 0) << file;
    const RealtimeMediaView& hm = host.media;
    ASSERT_GT(hm.num_grids, 0) << file;
    ASSERT_NE(hm.grid_records, nullptr) << file;
    const GridLightPod& last = hm.grids[hm.num_grids - 1];
    const size_t values =
        last.offset + static_cast<size_t>(hm.num_grid_lights) * last.r[0] * last.r[1] * last.r[2];
    const std::vector<float> host_T(hm.grid_light_T, hm.grid_light_T + values);
    const size_t columns = static_cast<size_t>(hm.grid_nx) * hm.grid_ny;
    const std::vector<float> host_t0(hm.grid_t0, hm.grid_t0 + columns);
    const std::vector<float> host_t1(hm.grid_t1, hm.grid_t1 + columns);
    const std::vector<GridFroxelRecord<Rgb4>> host_rec(
        hm.grid_records, hm.grid_records + columns * (kFroxelSlices + 1));
    RenderedFrame host_frame;
    cuda::RenderRealtimeOnHost(data, bvh, &pool, &host_frame, true);

    data.set_device_media(true);
    data.Prepare(snap, view, &pool, fx.get());
    cuda::RealtimeFrameView dev = data.View(bvh.view(), nullptr);
    EXPECT_EQ(dev.media_build.grids, 1) << file;
    EXPECT_NE(dev.media_build.grid_media, nullptr) << file;
    EXPECT_EQ(dev.media.grid_light_T, nullptr) << file;
    EXPECT_EQ(dev.media.grid_records, nullptr) << file;
    EXPECT_EQ(dev.media.grid_nx * dev.media.grid_ny, static_cast<int>(columns)) << file;
    cuda::MediaVolumeArrays built;
    cuda::BuildMediaVolumesOnHost(&dev, &pool, &built);
    EXPECT_EQ(built.grids.T, host_T) << file;
    ASSERT_EQ(built.grids.records.size(), host_rec.size()) << file;
    int met = 0, t_off = 0;
    for (size_t c = 0; c < columns; ++c) {
      const bool a = host_t0[c] < host_t1[c], b = built.grids.t0[c] < built.grids.t1[c];
      met += a ? 1 : 0;
      if (a != b) {
        ++t_off;  // a column that grazes a box's edge: met by one ray only
        continue;
      }
      const float tol = 1e-4f + 1e-5f * host_t1[c];
      if (std::abs(host_t0[c] - built.grids.t0[c]) > tol ||
          std::abs(host_t1[c] - built.grids.t1[c]) > tol)
        ++t_off;
    }
    float peak = 0, worst_S = 0, worst_T = 0;
    for (size_t i = 0; i < host_rec.size(); ++i) {
      const GridFroxelRecord<Rgb4>& a = host_rec[i];
      const GridFroxelRecord<Rgb4>& b = built.grids.records[i];
      peak = std::max({peak, a.S.x, a.S.y, a.S.z});
      worst_S = std::max(
          {worst_S, std::abs(a.S.x - b.S.x), std::abs(a.S.y - b.S.y), std::abs(a.S.z - b.S.z)});
      worst_T = std::max(
          {worst_T, std::abs(a.T.x - b.T.x), std::abs(a.T.y - b.T.y), std::abs(a.T.z - b.T.z)});
    }
    RenderedFrame dev_frame;
    cuda::RenderRealtimeOnHost(data, bvh, &pool, &dev_frame, true);
    const double psnr = realtime_parity::Psnr(host_frame.rgb, dev_frame.rgb);
    std::printf(
        "%s: grid light volumes %zu values (%s), grid froxels %zu columns (%d meet a grid, %d "
        "spans off), records: largest in-scatter difference %.3g of peak %.3g, transmittance "
        "%.3g; rgb PSNR device-built against host-built %.2f dB\n",
        file, host_T.size(), built.grids.T == host_T ? "equal" : "DIFFERENT", columns, met, t_off,
        worst_S, peak, worst_T, psnr);
    EXPECT_GT(met, 0) << file;
    EXPECT_LE(t_off, 0) << file;
    EXPECT_GT(peak, 0.0f) << file;
    EXPECT_LE(worst_S, 1e-5f * peak) << file;
    EXPECT_LE(worst_T, 1e-5f) << file;
    EXPECT_GE(psnr, 50.0) << file;
    EXPECT_EQ(host_frame.depth_m.data, dev_frame.depth_m.data) << file;
  }
}

}  // namespace
}  // namespace penumbra
