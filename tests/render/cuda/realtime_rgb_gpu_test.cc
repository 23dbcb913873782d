// the realtime tier's rgb and depth on the GPU (ctest label `gpu`) against the CPU backend on
// the bundled default, house, warehouse and outdoor worlds and effects/walkers.yaml (the mirror
// layer: its rover's materials have reflectance 0.2 and 0.4) at 640x480: rgb PSNR >= 40 dB, depth
// within 1 mm on >= 99.9 % of pixels, and two GPU renders bit-identical (rgb, radiance, depth);
// likewise a camera with lens distortion and a rolling shutter in the default room.
// without a device every test prints "skipped: no CUDA device".

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cstdio>
#include <string>

#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/render/cuda/cuda_renderer.h"
#include "realtime_parity.h"

namespace penumbra {
namespace {

// the CPU backend's frame of `view` (want) and two CudaRenderer renders of it (got, again), with
// how many frames the CudaRenderer rendered.
struct GpuFrames {
  RenderedFrame want, got, again;
  int64_t gpu_frames = 0;
};
GpuFrames RenderCpuAndGpuTwice(const SceneDescription& scene, const WorldSnapshot& snap,
                               const CameraView& view) {
  RenderSettings cpu_settings;
  cpu_settings.backend = RenderSettings::Backend::kEmbree;
  RenderSettings gpu_settings;
  gpu_settings.backend = RenderSettings::Backend::kCuda;
  GpuFrames f;
  MakeRenderer(scene, cpu_settings)->Render(snap, view, &f.want);
  const std::unique_ptr<Renderer> gpu = MakeRenderer(scene, gpu_settings);
  auto* g = dynamic_cast<cuda::CudaRenderer*>(gpu.get());
  EXPECT_NE(g, nullptr);
  if (g == nullptr) return f;
  gpu->Render(snap, view, &f.got);
  gpu->Render(snap, view, &f.again);
  f.gpu_frames = g->gpu_frames();
  return f;
}

class RealtimeRgbGpu : public ::testing::TestWithParam<std::string> {};

TEST_P(RealtimeRgbGpu, MatchesCpuBackendAndRepeatsBitForBit) {
  if (!ProbeCudaDevice().available) GTEST_SKIP() << "skipped: no CUDA device";
  const auto [session, snap, view, fx] = realtime_parity::LoadFrameAt(GetParam(), 1.0, 640, 480);
  const SceneDescription& scene = session->scene();
  const auto [want, got, again, gpu_frames] = RenderCpuAndGpuTwice(scene, snap, view);
  EXPECT_EQ(gpu_frames, 2);
  const double psnr = realtime_parity::Psnr(want.rgb, got.rgb);
  const double depth_bad = realtime_parity::DepthMismatch(want.depth_m, got.depth_m);
  std::printf(
      "%s 640x480 rgb+depth: PSNR %.2f dB (ev100 cpu %.4f gpu %.4f), depth > 1 mm on "
      "%.4f %% of pixels, second render %s\n",
      GetParam().c_str(), psnr, want.ev100, got.ev100, 100 * depth_bad,
      got.rgb.data == again.rgb.data && got.radiance.data == again.radiance.data &&
              got.depth_m.data == again.depth_m.data
          ? "bit-identical"
          : "DIFFERENT");
  EXPECT_GE(psnr, 40.0);
  EXPECT_LE(depth_bad, 0.001);
  EXPECT_EQ(got.rgb.data, again.rgb.data);
  EXPECT_EQ(got.radiance.data, again.radiance.data);
  EXPECT_EQ(got.depth_m.data, again.depth_m.data);
}

INSTANTIATE_TEST_SUITE_P(Bundled, RealtimeRgbGpu,
                         ::testing::Values("default.yaml", "house.yaml", "warehouse.yaml",
                                           "outdoor.yaml", "effects/walkers.yaml"));

// a camera with lens distortion and a rolling shutter renders on the GPU (its ray tables,
// camera_rays.h): rgb PSNR >= 40 dB and depth within 1 mm against the CPU backend, the
// segmentation equal on >= 99.9 % of pixels, the normals from the same rays, two renders
// bit-identical.
TEST(RealtimeRgbGpuCameras, DistortedRollingShutterCameraRendersOnTheGpu) {
  if (!ProbeCudaDevice().available) GTEST_SKIP() << "skipped: no CUDA device";
  auto [session, snap, view, fx] = realtime_parity::LoadFrameAt("default.yaml", 1.0, 640, 480);
  const SceneDescription& scene = session->scene();
  view.outputs[ImageKind::kSegmentation] = true;
  view.intrinsics.k1 = -0.28;
  view.intrinsics.k2 = 0.07;
  view.intrinsics.p1 = 0.002;
  view.motion.end_sec = 0.03;
  view.motion.line_time_sec = 0.03 / 480;
  view.motion.X_WO_end = view.X_WO;
  view.motion.X_WO_end.translation() += Eigen::Vector3d(0.15, 0.05, 0);
  const auto [want, got, again, gpu_frames] = RenderCpuAndGpuTwice(scene, snap, view);
  EXPECT_EQ(gpu_frames, 2);
  const double psnr = realtime_parity::Psnr(want.rgb, got.rgb);
  const double depth_bad = realtime_parity::DepthMismatch(want.depth_m, got.depth_m);
  int64_t seg_bad = 0;
  for (size_t i = 0; i < want.geom_id.data.size(); ++i)
    seg_bad += want.geom_id.data[i] != got.geom_id.data[i];
  std::printf(
      "default 640x480, distorted + rolling shutter: rgb PSNR %.2f dB, depth > 1 mm on %.4f %%, "
      "segmentation differs on %.4f %% of pixels\n",
      psnr, 100 * depth_bad, 100.0 * seg_bad / want.geom_id.data.size());
  EXPECT_GE(psnr, 40.0);
  EXPECT_LE(depth_bad, 0.001);
  EXPECT_LE(seg_bad, static_cast<int64_t>(want.geom_id.data.size() / 1000));
  EXPECT_EQ(got.rgb.data, again.rgb.data);
  EXPECT_EQ(got.depth_m.data, again.depth_m.data);
  EXPECT_EQ(got.geom_id.data, again.geom_id.data);
}

}  // namespace
}  // namespace penumbra
