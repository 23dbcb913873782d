// the CUDA backend's pathtraced tier, run on the CPU (TracePathtracedOnHost: the very
// PB_HOST_DEVICE per-pixel functions the path kernel runs, over the host BVH), against the CPU
// backend's PathIntegrator on the bundled default and house worlds (lamp spheres, the sun disc
// through the window, the daylight sky) at 64x48 and 16 samples per pixel, no denoiser: the
// radiance's mean relative difference at the scale of 8x8 blocks (path_parity.h) within
// kHostTileTolerance, and two renders bit-identical. dropping the sky or the lights from the GPU
// path moves it far beyond that (the metric can fail). no GPU needed.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <utility>

#include "path_parity.h"
#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/render/cuda/bvh_scene.h"
#include "penumbra/render/cuda/path_frame.h"
#include "penumbra/render/emitter_sampler.h"
#include "penumbra/render/media_scene.h"
#include "realtime_parity.h"

namespace penumbra {
namespace {

// the host path shares the CPU's random streams and (without fused multiply-adds) its rounding
// of every shared formula, so it tracks the CPU's estimate closely: what differs is where the BVH
// and Embree round a hit's distance and normal, after which a path may branch differently.
// measured: default 0.0000 %, house 0.23 % (without the sky 18.6 % and 88.2 %, without the
// lights 81.4 % and 16.8 %): issue 35's 1 %.
constexpr double kHostTileTolerance = 0.01;

struct HostPathtraced {
  RenderedFrame want;
  cuda::PathBuffers got, again, no_sky, no_lights;
  int W = 0, H = 0;
};

HostPathtraced RenderBoth(const std::string& world) {
  const std::unique_ptr<Session> session = realtime_parity::LoadSimulated(world);
  const SceneDescription& scene = session->scene();
  const WorldSnapshot snap = session->sim().Snapshot();
  const CameraView view = realtime_parity::RgbDepthView(scene, snap, 64, 48);
  const RenderSettings settings = path_parity::PathSettings(RenderSettings::Backend::kEmbree, 16);
  HostPathtraced r;
  r.W = 64, r.H = 48;
  MakeRenderer(scene, settings)->Render(snap, view, &r.want);
  cuda::BvhScene bvh(scene);
  bvh.Update(snap);
  cuda::RealtimeFrameData data(scene, settings);
  ThreadPool pool(0);
  // the bundled worlds have no emissive geom (their frames are on the GPU: PathNotOnGpu)
  EXPECT_TRUE(EmitterSampler(scene).empty());
  EXPECT_EQ(cuda::PathNotOnGpu(nullptr, view), "");
  data.Prepare(snap, view, &pool);
  const cuda::PathFrameView pf =
      cuda::PathView(data, data.View(bvh.view(), nullptr), data.frame_sky().sampling_pod());
  cuda::TracePathtracedOnHost(pf, &pool, &r.got);
  cuda::TracePathtracedOnHost(pf, &pool, &r.again);
  cuda::PathFrameView dropped = pf;
  dropped.sky_active = 0;
  cuda::TracePathtracedOnHost(dropped, &pool, &r.no_sky);
  dropped = pf;
  dropped.rt.num_lights = 0;
  cuda::TracePathtracedOnHost(dropped, &pool, &r.no_lights);
  return r;
}

ImageF RadianceOf(const cuda::PathBuffers& b, int W, int H) {
  ImageF img(W, H, 3);
  for (size_t i = 0; i < b.radiance.size(); ++i) {
    img.data[3 * i] = b.radiance[i].x;
    img.data[3 * i + 1] = b.radiance[i].y;
    img.data[3 * i + 2] = b.radiance[i].z;
  }
  return img;
}

class PathtracedHostPath : public ::testing::TestWithParam<std::string> {};

TEST_P(PathtracedHostPath, TracksTheCpuBackendsEstimate) {
  const HostPathtraced r = RenderBoth(GetParam());
  const ImageF got = RadianceOf(r.got, r.W, r.H);
  const double tile = path_parity::TileRelativeDifference(got, r.want.radiance);
  const double mean = path_parity::MeanRelativeDifference(got, r.want.radiance);
  const double no_sky =
      path_parity::TileRelativeDifference(RadianceOf(r.no_sky, r.W, r.H), r.want.radiance);
  const double no_lights =
      path_parity::TileRelativeDifference(RadianceOf(r.no_lights, r.W, r.H), r.want.radiance);
  std::printf(
      "%s 64x48 16 spp: radiance mean relative difference %.4f %% (8x8 blocks), %.4f %% (image "
      "mean); without the sky %.2f %%, without the lights %.2f %%\n",
      GetParam().c_str(), 100 * tile, 100 * mean, 100 * no_sky, 100 * no_lights);
  EXPECT_LE(tile, kHostTileTolerance);
  EXPECT_GT(no_sky, kHostTileTolerance);
  EXPECT_GT(no_lights, kHostTileTolerance);
  EXPECT_EQ(0, std::memcmp(r.got.radiance.data(), r.again.radiance.data(),
                           sizeof(Float3) * r.got.radiance.size()));
}

INSTANTIATE_TEST_SUITE_P(Bundled, PathtracedHostPath,
                         ::testing::Values("default.yaml", "house.yaml"));

// the default room with emissive lamp diffusers (path_parity.h): the GPU path samples the
// emissive geoms as EmitterSampler does (render/emitter_math.h), with MIS at the hits they light;
// against the CPU backend as above (1 %).
TEST(PathtracedHostPath, EmissiveGeomsTrackTheCpuBackendsEstimate) {
  const std::unique_ptr<Session> session = realtime_parity::LoadSimulated("default.yaml");
  SceneDescription scene = session->scene();
  ASSERT_TRUE(path_parity::MakeDiffusersEmissive(&scene));
  const WorldSnapshot snap = session->sim().Snapshot();
  const CameraView view = realtime_parity::RgbDepthView(scene, snap, 64, 48);
  const RenderSettings settings = path_parity::PathSettings(RenderSettings::Backend::kEmbree, 16);
  RenderedFrame want;
  MakeRenderer(scene, settings)->Render(snap, view, &want);
  const EmitterSampler sampler(scene);
  ASSERT_FALSE(sampler.empty());
  cuda::PathEmitterHost emitters(sampler);
  emitters.SetPoses(sampler, snap.X_WB);
  cuda::BvhScene bvh(scene);
  bvh.Update(snap);
  cuda::RealtimeFrameData data(scene, settings);
  ThreadPool pool(0);
  data.Prepare(snap, view, &pool);
  cuda::PathFrameView pf =
      cuda::PathView(data, data.View(bvh.view(), nullptr), data.frame_sky().sampling_pod());
  pf.emitters = emitters.View();
  cuda::PathBuffers got, unsampled;
  cuda::TracePathtracedOnHost(pf, &pool, &got);
  // without the emitter sampling (their light then comes by BSDF sampling alone, weight 1): the
  // paths differ from the CPU's, so the emitters are sampled above
  pf.emitters = cuda::PathEmitters{};
  cuda::TracePathtracedOnHost(pf, &pool, &unsampled);
  const double tile = path_parity::TileRelativeDifference(RadianceOf(got, 64, 48), want.radiance);
  const double tile_unsampled =
      path_parity::TileRelativeDifference(RadianceOf(unsampled, 64, 48), want.radiance);
  std::printf(
      "default, emissive diffusers (%d emitters), 64x48 16 spp: radiance mean relative "
      "difference %.4f %% (8x8 blocks); without the emitter sampling %.2f %%\n",
      sampler.size(), 100 * tile, 100 * tile_unsampled);
  EXPECT_LE(tile, kHostTileTolerance);
  EXPECT_GT(tile_unsampled, tile);
}

// the finished frame (RenderPathtracedOnHost: the denoiser and the film after the paths) has
// the CPU backend's outputs: rgb and depth of the camera's size, depth within 1 mm.
TEST(PathtracedHostPath, FinishedFrameHasTheCpuBackendsOutputs) {
  const std::unique_ptr<Session> session = realtime_parity::LoadSimulated("default.yaml");
  const SceneDescription& scene = session->scene();
  const WorldSnapshot snap = session->sim().Snapshot();
  const CameraView view = realtime_parity::RgbDepthView(scene, snap, 64, 48);
  RenderSettings settings = path_parity::PathSettings(RenderSettings::Backend::kEmbree, 4);
  settings.denoise = true;
  RenderedFrame want, got;
  MakeRenderer(scene, settings)->Render(snap, view, &want);
  cuda::BvhScene bvh(scene);
  bvh.Update(snap);
  cuda::RealtimeFrameData data(scene, settings);
  ThreadPool pool(0);
  data.Prepare(snap, view, &pool);
  cuda::RenderPathtracedOnHost(data, bvh, &pool, &got);
  ASSERT_EQ(got.rgb.width, 64);
  ASSERT_EQ(got.rgb.height, 48);
  EXPECT_LE(realtime_parity::DepthMismatch(want.depth_m, got.depth_m), 0.001);
  std::printf("default 64x48 4 spp denoised: rgb PSNR %.2f dB, ev100 cpu %.3f host-gpu-path %.3f\n",
              realtime_parity::Psnr(want.rgb, got.rgb), want.ev100, got.ev100);
  EXPECT_GE(realtime_parity::Psnr(want.rgb, got.rgb), 25.0);
}

// the GPU's split of a pixel's samples into runs (PathRunsPerPixel; PathSampleRange per run,
// the runs added in run order) estimates what one run does: the same paths, only the double
// sums' rounding differs (relative 1e-6 at most); and the run count fills the threads asked for.
TEST(PathtracedHostPath, SampleRunsAddUpToThePixelsEstimate) {
  EXPECT_EQ(cuda::PathRunsPerPixel(128 * 96, 1024, 1 << 18), 22);
  EXPECT_EQ(cuda::PathRunsPerPixel(640 * 480, 64, 1 << 18), 1);
  EXPECT_EQ(cuda::PathRunsPerPixel(16, 4, 1 << 18), 4);
  const std::unique_ptr<Session> session = realtime_parity::LoadSimulated("default.yaml");
  const SceneDescription& scene = session->scene();
  const WorldSnapshot snap = session->sim().Snapshot();
  const CameraView view = realtime_parity::RgbDepthView(scene, snap, 32, 24);
  const RenderSettings settings = path_parity::PathSettings(RenderSettings::Backend::kEmbree, 12);
  cuda::BvhScene bvh(scene);
  bvh.Update(snap);
  cuda::RealtimeFrameData data(scene, settings);
  ThreadPool pool(0);
  data.Prepare(snap, view, &pool);
  const cuda::PathFrameView pf =
      cuda::PathView(data, data.View(bvh.view(), nullptr), data.frame_sky().sampling_pod());
  for (int v = 0; v < 24; v += 5) {
    for (int u = 0; u < 32; u += 7) {
      const cuda::PathPartial whole = cuda::PathSampleRange<false>(pf, u, v, 0, 12);
      cuda::PathPartial runs;
      for (int k = 0; k < 5; ++k) {
        // runs of 3 samples, the last one empty (as the kernel's)
        const cuda::PathPartial q =
            cuda::PathSampleRange<false>(pf, u, v, std::min(3 * k, 12), std::min(3 * k + 3, 12));
        for (int c = 0; c < 3; ++c) runs.L[c] += q.L[c], runs.albedo[c] += q.albedo[c];
        runs.albedo_count += q.albedo_count;
      }
      EXPECT_EQ(runs.albedo_count, whole.albedo_count);
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(runs.L[c], whole.L[c], 1e-6 * std::abs(whole.L[c]) + 1e-12);
    }
  }
}

// worlds/effects/<world> at 1 s through camera `camera` at w x h (rgb and depth) with its effects
// frame: the pathtraced tier's media on the GPU path (fog: homogeneous; smoke_plume: a grid).
struct MediaFrameCase {
  std::unique_ptr<Session> session;
  WorldSnapshot snap;
  CameraView view;
  std::shared_ptr<const EffectsFrame> fx;
};

MediaFrameCase LoadMediaFrame(const std::string& world, int camera, int w, int h) {
  MediaFrameCase c;
  c.session = realtime_parity::LoadSimulatedAt("effects/" + world, 1.0);
  const SceneDescription& scene = c.session->scene();
  c.snap = c.session->sim().Snapshot();
  c.view = realtime_parity::RgbDepthView(scene, c.snap, w, h);
  const CameraSpec& cam = scene.cameras.at(camera);
  c.view.X_WO = CameraPoseInWorld(cam, c.snap);
  c.view.intrinsics = CameraIntrinsics::FromFovy(w, h, cam.intrinsics.fovy_deg());
  c.fx = c.session->effects().Evaluate(c.snap, c.view.X_WO.translation());
  return c;
}

// the GPU path with media (TracePath<true>: the free flights' delta tracking, the phase
// function's next events and samples, the media's transmittance on every shadow ray; the shared
// formulas of render/media_scene_math.h), run on the CPU, against the CPU backend's
// PathIntegrator: fog (homogeneous; the rover's camera) and smoke_plume (a grid; the overview
// camera, which sees the plume), 64x48, 16 spp. the paths draw the CPU's random numbers, so
// they track its estimate closely; without the media (the paths of clear air) the difference
// is far larger (the metric can fail).
class PathtracedHostMedia : public ::testing::TestWithParam<std::pair<std::string, int>> {};

TEST_P(PathtracedHostMedia, TracksTheCpuBackendsEstimate) {
  const std::string world = GetParam().first;
  const MediaFrameCase c = LoadMediaFrame(world, GetParam().second, 64, 48);
  ASSERT_TRUE(c.fx);
  ASSERT_FALSE(c.fx->homogeneous_media.empty() && c.fx->grid_media.empty());
  EXPECT_EQ(cuda::PathNotOnGpu(c.fx.get(), c.view), "");
  const SceneDescription& scene = c.session->scene();
  const RenderSettings settings = path_parity::PathSettings(RenderSettings::Backend::kEmbree, 16);
  RenderedFrame want;
  MakeRenderer(scene, settings)->Render(c.snap, c.fx.get(), c.view, &want);
  cuda::BvhScene bvh(scene);
  bvh.Update(c.snap);
  cuda::RealtimeFrameData data(scene, settings);
  ThreadPool pool(0);
  EffectsFrame storage;
  data.Prepare(c.snap, c.view, &pool, cuda::EffectsWithoutMedia(c.fx.get(), &storage));
  EXPECT_FALSE(data.has_media());  // the realtime tier's media volumes are not built
  MediaScene media;
  media.Build(c.fx.get());
  cuda::PathFrameView pf =
      cuda::PathView(data, data.View(bvh.view(), nullptr), data.frame_sky().sampling_pod());
  pf.media = media.View();
  cuda::PathBuffers got, again, clear;
  cuda::TracePathtracedOnHost(pf, &pool, &got);
  cuda::TracePathtracedOnHost(pf, &pool, &again);
  pf.media = MediaSceneView();
  cuda::TracePathtracedOnHost(pf, &pool, &clear);
  const double tile = path_parity::TileRelativeDifference(RadianceOf(got, 64, 48), want.radiance);
  const double mean = path_parity::MeanRelativeDifference(RadianceOf(got, 64, 48), want.radiance);
  const double tile_clear =
      path_parity::TileRelativeDifference(RadianceOf(clear, 64, 48), want.radiance);
  std::printf(
      "%s 64x48 16 spp (%zu homogeneous, %zu grids): radiance mean relative difference %.4f %% "
      "(8x8 blocks), %.4f %% (image mean); without the media %.2f %%\n",
      world.c_str(), media.analytic().size(), media.grids().size(), 100 * tile, 100 * mean,
      100 * tile_clear);
  EXPECT_LE(tile, kHostTileTolerance);
  EXPECT_GT(tile_clear, 5 * kHostTileTolerance);
  EXPECT_EQ(0, std::memcmp(got.radiance.data(), again.radiance.data(),
                           sizeof(Float3) * got.radiance.size()));
}

INSTANTIATE_TEST_SUITE_P(Effects, PathtracedHostMedia,
                         ::testing::Values(std::make_pair(std::string("fog.yaml"), 0),
                                           std::make_pair(std::string("smoke_plume.yaml"), 1)));

// pathtraced frames with particles, or with a distorted or moving camera, go to the CPU renderer
// (the path kernels trace no streaks); frames with media (homogeneous or grids) stay on the GPU
// since branch gpu14.
TEST(PathNotOnGpu, ParticlesAndDistortedCamerasGoToTheCpuMediaDoNot) {
  CameraView view;
  view.intrinsics = CameraIntrinsics::FromFovy(64, 48, 60.0);
  EXPECT_EQ(cuda::PathNotOnGpu(nullptr, view), "");
  EffectsFrame fog;
  fog.homogeneous_media.emplace_back();
  EXPECT_EQ(cuda::EffectsNotOnGpu(&fog), "");
  EXPECT_EQ(cuda::PathNotOnGpu(&fog, view), "");
  EffectsFrame smoke;
  smoke.grid_media.emplace_back();
  EXPECT_EQ(cuda::PathNotOnGpu(&smoke, view), "");
  // the realtime tier's media volumes are not built for the paths: Prepare gets the effects
  // without their media
  EffectsFrame storage;
  EXPECT_EQ(cuda::EffectsWithoutMedia(&fog, &storage), nullptr);
  fog.surface_wetness = 0.5f;
  const EffectsFrame* lit = cuda::EffectsWithoutMedia(&fog, &storage);
  ASSERT_NE(lit, nullptr);
  EXPECT_TRUE(lit->homogeneous_media.empty());
  EXPECT_EQ(lit->surface_wetness, 0.5f);
  EffectsFrame rain;
  rain.particles.emplace_back();
  EXPECT_NE(cuda::PathNotOnGpu(&rain, view).find("particles"), std::string::npos);
  CameraView distorted = view;
  distorted.intrinsics.k1 = 0.1;
  EXPECT_NE(cuda::PathNotOnGpu(nullptr, distorted).find("distorted"), std::string::npos);
}

}  // namespace
}  // namespace penumbra
