// the realtime frame's exposure on the device and the uploads it skips change no output bit
// (ctest label `gpu`; without a device every test prints "skipped: no CUDA device"):
// - DeviceFrameExposure (film_math.h's FrameExposure run by the exposure kernel) computes the
//   host's function: over 2,000 sets of row sums its EV100 is within a few ulps of the host's
//   (the device's double exp, log2 and exp2 need not round as the C library's do);
// - Render() with the exposure on the device, with auto and manual exposure, compensation and
//   white-balance gains, in the default room and the house at 640x480: every frame's device
//   exposure is checked against the host's, two renders are bit-identical, and without the
//   radiance asked for (CudaRenderer::set_radiance_output) the rgb, depth and EV100 are the same;
// - a renderer that skipped the unchanged uploads and transforms of earlier frames
//   (DeviceRealtime::Render, RealtimeFrameData::PoseWorld) renders a later snapshot, after the
//   bodies moved, with the bits of a renderer made for that snapshot alone.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "penumbra/core/rng.h"
#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/render/cuda/cuda_renderer.h"
#include "penumbra/render/film/film.h"
#include "realtime_parity.h"

namespace penumbra {
namespace {

TEST(RealtimeExposureGpu, DeviceFrameExposureIsTheHostFunction) {
  if (!ProbeCudaDevice().available) GTEST_SKIP() << "skipped: no CUDA device";
  const int W = 640, H = 480;
  const int64_t pixels = static_cast<int64_t>(W) * H;
  int ev_differs = 0, exposure_differs = 0;
  double worst = 0;
  for (int k = 0; k < 2000; ++k) {
    // row sums of W pixels with ln L around a level that moves from set to set
    const double level = -6.0 + 12.0 * (k / 1999.0);
    std::vector<double> rows(H);
    for (int v = 0; v < H; ++v) {
      const uint64_t h = HashKeys(static_cast<uint64_t>(k), static_cast<uint64_t>(v));
      rows[v] = W * (level + 2.0 * (static_cast<double>(h >> 11) * 0x1.0p-53 - 0.5));
    }
    FilmExposurePod film;
    film.auto_exposure = k % 7 == 6 ? 0 : 1;
    film.ev100 = 3.0 + 0.01 * k;
    film.compensation_ev = (k % 5) * 0.3 - 0.6;
    const float gains[3] = {1.0f + 0.001f * (k % 11), 1.0f, 0.9f};
    float host[3], device[3];
    const double host_ev = FrameExposure(film, rows.data(), H, pixels, kMinLuminance, gains, host);
    const double device_ev = cuda::DeviceFrameExposure(film, rows, pixels, gains, device);
    ev_differs += std::memcmp(&host_ev, &device_ev, sizeof(double)) != 0;
    exposure_differs += std::memcmp(host, device, sizeof(host)) != 0;
    worst = std::max(worst, std::abs(device_ev - host_ev) / std::max(1.0, std::abs(host_ev)));
    ASSERT_NEAR(device_ev, host_ev, 1e-14 * std::max(1.0, std::abs(host_ev))) << k;
    for (int c = 0; c < 3; ++c) ASSERT_NEAR(device[c], host[c], 1e-6f * host[c]) << k << " " << c;
  }
  std::printf(
      "device exposure against the host's over 2000 sets: EV100 differs in %d (worst "
      "relative %.3g), float exposures in %d\n",
      ev_differs, worst, exposure_differs);
  EXPECT_LE(exposure_differs, 20);  // the last bits of a few; Render develops those again
}

class RealtimeExposureRender : public ::testing::TestWithParam<std::string> {};

TEST_P(RealtimeExposureRender, DeviceExposureRendersRepeatably) {
  if (!ProbeCudaDevice().available) GTEST_SKIP() << "skipped: no CUDA device";
  const std::unique_ptr<Session> session = realtime_parity::LoadSimulated(GetParam());
  const SceneDescription& scene = session->scene();
  const WorldSnapshot snap = session->sim().Snapshot();
  for (int s = 0; s < 3; ++s) {
    RenderSettings settings;
    settings.backend = RenderSettings::Backend::kCuda;
    CameraView view = realtime_parity::RgbDepthView(scene, snap, 640, 480);
    if (s == 1) settings.exposure_compensation_ev = 0.7;
    if (s == 2) {
      settings.auto_exposure = false;
      settings.ev100 = 6.5;
      settings.exposure_compensation_ev = -0.4;
      view.white_balance_gains = Eigen::Vector3f(1.2f, 1.0f, 0.85f);
    }
    const std::unique_ptr<Renderer> gpu = MakeRenderer(scene, settings);
    auto* g = dynamic_cast<cuda::CudaRenderer*>(gpu.get());
    ASSERT_NE(g, nullptr);
    cuda::DeviceRealtime& rt = g->device_realtime();
    RenderedFrame got, again;
    gpu->Render(snap, view, &got);
    gpu->Render(snap, view, &again);
    const cuda::RealtimeExposureChecks& x = rt.exposure_checks();
    std::printf(
        "%s settings %d: rgb %s, radiance %s, depth %s, ev100 %.17g / %.17g; device "
        "exposures %lld, EV100 differs %lld, developed again %lld\n",
        GetParam().c_str(), s, again.rgb.data == got.rgb.data ? "same" : "DIFFERENT",
        again.radiance.data == got.radiance.data ? "same" : "DIFFERENT",
        again.depth_m.data == got.depth_m.data ? "same" : "DIFFERENT", again.ev100, got.ev100,
        static_cast<long long>(x.frames), static_cast<long long>(x.ev100_differs),
        static_cast<long long>(x.redeveloped));
    EXPECT_EQ(x.frames, 2);
    EXPECT_FALSE(got.rgb.empty()) << s;
    EXPECT_FALSE(got.radiance.empty()) << s;
    EXPECT_EQ(again.rgb.data, got.rgb.data) << s;
    EXPECT_EQ(again.radiance.data, got.radiance.data) << s;
    EXPECT_EQ(again.depth_m.data, got.depth_m.data) << s;
    EXPECT_EQ(again.ev100, got.ev100) << s;
    // without the radiance asked for: the same rgb, depth and EV100, no radiance
    g->set_radiance_output(false);
    RenderedFrame lean;
    gpu->Render(snap, view, &lean);
    EXPECT_TRUE(lean.radiance.empty()) << s;
    EXPECT_EQ(lean.rgb.data, got.rgb.data) << s;
    EXPECT_EQ(lean.depth_m.data, got.depth_m.data) << s;
    EXPECT_EQ(lean.ev100, got.ev100) << s;
  }
}

TEST_P(RealtimeExposureRender, SkippedUploadsFollowMovingBodies) {
  if (!ProbeCudaDevice().available) GTEST_SKIP() << "skipped: no CUDA device";
  const std::unique_ptr<Session> session = realtime_parity::LoadSimulated(GetParam());
  const SceneDescription& scene = session->scene();
  const WorldSnapshot first = session->sim().Snapshot();
  RenderSettings settings;
  settings.backend = RenderSettings::Backend::kCuda;
  const std::unique_ptr<Renderer> gpu = MakeRenderer(scene, settings);
  const CameraView view = realtime_parity::RgbDepthView(scene, first, 640, 480);
  RenderedFrame earlier;
  gpu->Render(first, view, &earlier);
  gpu->Render(first, view, &earlier);
  while (session->sim().time() < 2.0) session->sim().Step();
  const WorldSnapshot later = session->sim().Snapshot();
  int moved = 0;
  for (size_t b = 0; b < later.X_WB.size(); ++b)
    moved += later.X_WB[b].matrix() != first.X_WB[b].matrix();
  RenderedFrame got, want;
  gpu->Render(later, view, &got);
  const std::unique_ptr<Renderer> fresh = MakeRenderer(scene, settings);
  fresh->Render(later, view, &want);
  std::printf("%s: %d bodies moved; rgb %s, radiance %s, depth %s\n", GetParam().c_str(), moved,
              got.rgb.data == want.rgb.data ? "same" : "DIFFERENT",
              got.radiance.data == want.radiance.data ? "same" : "DIFFERENT",
              got.depth_m.data == want.depth_m.data ? "same" : "DIFFERENT");
  EXPECT_EQ(got.rgb.data, want.rgb.data);
  EXPECT_EQ(got.radiance.data, want.radiance.data);
  EXPECT_EQ(got.depth_m.data, want.depth_m.data);
  EXPECT_EQ(got.ev100, want.ev100);
}

INSTANTIATE_TEST_SUITE_P(Bundled, RealtimeExposureRender,
                         ::testing::Values("default.yaml", "house.yaml"));

}  // namespace
}  // namespace penumbra
