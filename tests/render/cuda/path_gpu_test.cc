// the pathtraced tier on the GPU (ctest label `gpu`) against the CPU backend on the bundled
// default and house worlds, the default room with emissive lamp diffusers and with a distorted,
// moving camera, and the effects worlds with media (fog, smoke_plume) and particles (rain, snow):
// the first camera at 128x96 after 1 s, 1024 samples per pixel, 4 bounces, no denoiser;
// the radiance's mean relative difference at the scale of 8x8 blocks and of the image mean
// (path_parity.h) <= 1 %, the frame rendered on the GPU (not the CPU fallback), and two GPU
// renders bit-identical (radiance and rgb). without a device every test prints "skipped: no CUDA
// device".

#include <gtest/gtest.h>

#include <cstdio>
#include <memory>
#include <string>
#include <utility>

#include "path_parity.h"
#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/render/cuda/cuda_renderer.h"
#include "realtime_parity.h"

namespace penumbra {
namespace {

// the frame of `view` under `fx` (null: none) at 1024 spp on the CPU backend (all cores) and
// twice on the GPU: both GPU frames on the GPU, the radiance's mean relative difference (8x8
// blocks and image mean) <= 1 %, depth within 1 mm on >= 99.9 %, the GPU renders bit-identical.
// `cpu_out` (may be null): the CPU backend's frame; `tile_out` (may be null): the 8x8-block
// difference.
void ExpectGpuTracksCpu(const std::string& label, const SceneDescription& scene,
                        const WorldSnapshot& snap, const EffectsFrame* fx, const CameraView& view,
                        RenderedFrame* cpu_out = nullptr, double* tile_out = nullptr) {
  RenderSettings cpu_settings = path_parity::PathSettings(RenderSettings::Backend::kEmbree, 1024);
  cpu_settings.threads = 0;
  const RenderSettings gpu_settings =
      path_parity::PathSettings(RenderSettings::Backend::kCuda, 1024);
  RenderedFrame want, got, again;
  MakeRenderer(scene, cpu_settings)->Render(snap, fx, view, &want);
  const std::unique_ptr<Renderer> gpu = MakeRenderer(scene, gpu_settings);
  auto* g = dynamic_cast<cuda::CudaRenderer*>(gpu.get());
  ASSERT_NE(g, nullptr);
  gpu->Render(snap, fx, view, &got);
  gpu->Render(snap, fx, view, &again);
  EXPECT_EQ(g->gpu_frames(), 2);
  const double tile = path_parity::TileRelativeDifference(got.radiance, want.radiance);
  const double mean = path_parity::MeanRelativeDifference(got.radiance, want.radiance);
  std::printf(
      "%s 128x96 1024 spp: radiance mean relative difference %.3f %% (8x8 blocks), %.3f %% "
      "(image mean); ev100 cpu %.4f gpu %.4f; depth > 1 mm on %.4f %% of pixels\n",
      label.c_str(), 100 * tile, 100 * mean, want.ev100, got.ev100,
      100 * realtime_parity::DepthMismatch(want.depth_m, got.depth_m));
  EXPECT_LE(tile, 0.01);
  EXPECT_LE(mean, 0.01);
  EXPECT_LE(realtime_parity::DepthMismatch(want.depth_m, got.depth_m), 0.001);
  EXPECT_EQ(got.radiance.data, again.radiance.data);
  EXPECT_EQ(got.rgb.data, again.rgb.data);
  if (tile_out != nullptr) *tile_out = tile;
  if (cpu_out != nullptr) *cpu_out = std::move(want);
}

class PathtracedGpu : public ::testing::TestWithParam<std::string> {};

TEST_P(PathtracedGpu, MatchesCpuBackendAt1024SppAndRepeatsBitForBit) {
  if (!ProbeCudaDevice().available) GTEST_SKIP() << "skipped: no CUDA device";
  // "default-emissive.yaml": the default room with its lamp diffusers glowing;
  // "default-distorted-moving.yaml": its camera with lens distortion and a rolling shutter over
  // a moving, turning camera (path_parity.h)
  const bool emissive = GetParam() == "default-emissive.yaml";
  const bool distorted = GetParam() == "default-distorted-moving.yaml";
  const std::unique_ptr<Session> session =
      realtime_parity::LoadSimulated(emissive || distorted ? "default.yaml" : GetParam());
  SceneDescription scene = session->scene();
  if (emissive) {
    ASSERT_TRUE(path_parity::MakeDiffusersEmissive(&scene));
  }
  const WorldSnapshot snap = session->sim().Snapshot();
  CameraView view = realtime_parity::RgbDepthView(scene, snap, 128, 96);
  if (distorted) path_parity::DistortAndMove(&view);
  ExpectGpuTracksCpu(GetParam(), scene, snap, nullptr, view);
}

INSTANTIATE_TEST_SUITE_P(Bundled, PathtracedGpu,
                         ::testing::Values("default.yaml", "house.yaml", "default-emissive.yaml",
                                           "default-distorted-moving.yaml"));

// the pathtraced tier's media on the GPU (render/transport/path_trace.h's TracePath<true> over
// the shared formulas of render/media/media_scene_math.h): worlds/effects/fog.yaml (homogeneous
// fog, the rover's camera) and smoke_plume.yaml (a smoke grid, the overview camera, which sees the
// plume) at 1 s, 128x96, 1024 spp, 4 bounces, no denoiser, against the CPU backend on all
// cores: the radiance's mean relative difference (8x8 blocks and image mean) <= 1 %, the frame
// on the GPU (not the CPU fallback), two GPU renders bit-identical.
class PathtracedGpuMedia : public ::testing::TestWithParam<std::pair<std::string, int>> {};

TEST_P(PathtracedGpuMedia, MatchesCpuBackendAt1024SppAndRepeatsBitForBit) {
  if (!ProbeCudaDevice().available) GTEST_SKIP() << "skipped: no CUDA device";
  const std::string world = GetParam().first;
  const std::unique_ptr<Session> session =
      realtime_parity::LoadSimulatedAt("effects/" + world, 1.0);
  const SceneDescription& scene = session->scene();
  const WorldSnapshot snap = session->sim().Snapshot();
  CameraView view = realtime_parity::RgbDepthView(scene, snap, 128, 96);
  const CameraSpec& cam = scene.cameras.at(GetParam().second);
  view.X_WO = CameraPoseInWorld(cam, snap);
  view.intrinsics = CameraIntrinsics::FromFovy(128, 96, cam.intrinsics.fovy_deg());
  const std::shared_ptr<const EffectsFrame> fx =
      session->effects().Evaluate(snap, view.X_WO.translation());
  ASSERT_TRUE(fx);
  ASSERT_FALSE(fx->homogeneous_media.empty() && fx->grid_media.empty());
  ExpectGpuTracksCpu(world, scene, snap, fx.get(), view);
}

INSTANTIATE_TEST_SUITE_P(Effects, PathtracedGpuMedia,
                         ::testing::Values(std::make_pair(std::string("fog.yaml"), 0),
                                           std::make_pair(std::string("smoke_plume.yaml"), 1)));

// the pathtraced tier's particles on the GPU (render/transport/path_streaks.h: the camera rays
// meet the frame's streaks through a BVH, one draw against the streak's coverage, its radiance
// from ShadeStreak): worlds/effects/rain.yaml and snow.yaml (the rover's camera) at 1 s, 128x96,
// 1024 spp, 4 bounces, no denoiser, against the CPU backend on all cores: the radiance's mean
// relative difference (8x8 blocks and image mean) <= 1 %, the frame on the GPU (not the CPU
// fallback), two GPU renders bit-identical; and, since the streaks change the image by less
// than 1 % at the block scale, the GPU frame of the same effects without the particles differs
// from the CPU's by more than 3 times the GPU frame with them (so the test can fail).
class PathtracedGpuParticles : public ::testing::TestWithParam<std::string> {};

TEST_P(PathtracedGpuParticles, MatchesCpuBackendAt1024SppAndRepeatsBitForBit) {
  if (!ProbeCudaDevice().available) GTEST_SKIP() << "skipped: no CUDA device";
  const realtime_parity::WorldFrame f =
      realtime_parity::LoadFrameAt("effects/" + GetParam(), 1.0, 128, 96);
  const SceneDescription& scene = f.session->scene();
  const WorldSnapshot& snap = f.snap;
  const CameraView& view = f.view;
  ASSERT_TRUE(f.fx);
  ASSERT_FALSE(f.fx->particles.empty());
  RenderedFrame want, clear;
  double tile = 1;
  ExpectGpuTracksCpu(GetParam(), scene, snap, f.fx.get(), view, &want, &tile);
  EffectsFrame no_particles = *f.fx;
  no_particles.particles.clear();
  const RenderSettings gpu_settings =
      path_parity::PathSettings(RenderSettings::Backend::kCuda, 1024);
  MakeRenderer(scene, gpu_settings)->Render(snap, &no_particles, view, &clear);
  const double tile_clear = path_parity::TileRelativeDifference(clear.radiance, want.radiance);
  std::printf("%s without the particles: %.3f %% (8x8 blocks)\n", GetParam().c_str(),
              100 * tile_clear);
  EXPECT_GT(tile_clear, 3 * tile);
}

INSTANTIATE_TEST_SUITE_P(Effects, PathtracedGpuParticles,
                         ::testing::Values("rain.yaml", "snow.yaml"));

}  // namespace
}  // namespace penumbra
