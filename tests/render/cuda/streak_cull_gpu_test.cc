// the drops culled on the device (ctest label `gpu`: CudaRenderer's, cuda_streak_cull.h) against
// the host's culling (a CudaRenderer whose RealtimeFrameData has no device drop culler): rain, snow
// and rain in fog (realtime_parity::AddRainFog: a height fog and a box of haze, more rain culled as
// invisible) at 1 s, 640x480, with the still camera, and rain and snow with a turning
// rolling-shutter camera (realtime_parity::AddRollingShutter): the same streaks (count, order,
// sets, ends, widened radii, coverage: the splat's StreakPods byte for byte) and culled count, and
// the same rgb, radiance, depth and EV100 bits. DeviceStreakCull run alone on the frame's decision
// inputs with the exposure time changed by one part in a thousand gives other streaks (the
// comparison can fail); a drop with a non-finite position throws the host's ConfigError, naming it.
// the streaks stay on the device and Render reads the culling's counts with the frame's outputs: a
// frame with a non-finite drop still throws that ConfigError from its Render call, and the next
// frame is clean. without a device every test prints "skipped: no CUDA device".

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "penumbra/core/error.h"
#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/render/cuda/cuda_renderer.h"
#include "penumbra/render/cuda/cuda_streak_cull.h"
#include "penumbra/render/frame/realtime_frame.h"
#include "realtime_parity.h"

namespace penumbra {
namespace {

std::unique_ptr<Renderer> GpuRenderer(const SceneDescription& scene) {
  RenderSettings settings;
  settings.backend = RenderSettings::Backend::kCuda;
  return MakeRenderer(scene, settings);
}

// a GPU renderer whose realtime frames cull their drops on the host (ParticleStreaks::Build)
std::unique_ptr<Renderer> HostCullingRenderer(const SceneDescription& scene) {
  std::unique_ptr<Renderer> r = GpuRenderer(scene);
  auto* g = dynamic_cast<cuda::CudaRenderer*>(r.get());
  if (g != nullptr)
    g->realtime_frame().set_device_drop_culler(cuda::RealtimeFrameData::DeviceDropCuller());
  return r;
}

std::vector<cuda::StreakPod> SplatPods(cuda::CudaRenderer* g) {
  const cuda::PathStreaks list = g->realtime_frame().splat_streaks().View();
  return std::vector<cuda::StreakPod>(list.streaks, list.streaks + list.num);
}

bool SamePods(const std::vector<cuda::StreakPod>& a, const std::vector<cuda::StreakPod>& b) {
  return a.size() == b.size() &&
         std::memcmp(a.data(), b.data(), sizeof(cuda::StreakPod) * a.size()) == 0;
}

TEST(StreakCullGpu, DeviceCullingGivesTheHostCullingsStreaksAndBits) {
  if (!ProbeCudaDevice().available) GTEST_SKIP() << "skipped: no CUDA device";
  struct Case {
    const char* file;
    bool rolling, fog;
  };
  for (const Case& k :
       {Case{"effects/rain.yaml", false, false}, Case{"effects/rain.yaml", true, false},
        Case{"effects/snow.yaml", false, false}, Case{"effects/snow.yaml", true, false},
        Case{"effects/rain.yaml", false, true}}) {
    {
      const char* file = k.file;
      const bool rolling = k.rolling;
      SCOPED_TRACE(std::string(file) + (rolling ? ", rolling shutter" : ", still camera") +
                   (k.fog ? ", in fog" : ""));
      auto [session, snap, view, loaded] = realtime_parity::LoadFrameAt(file, 1.0, 640, 480);
      ASSERT_TRUE(loaded && !loaded->particles.empty());
      auto fx = std::make_shared<EffectsFrame>(*loaded);
      if (k.fog) realtime_parity::AddRainFog(fx.get());
      if (rolling) realtime_parity::AddRollingShutter(&view);
      const std::unique_ptr<Renderer> gpu = GpuRenderer(session->scene());
      auto* g = dynamic_cast<cuda::CudaRenderer*>(gpu.get());
      ASSERT_NE(g, nullptr);
      const std::unique_ptr<Renderer> host_gpu = HostCullingRenderer(session->scene());
      auto* hg = dynamic_cast<cuda::CudaRenderer*>(host_gpu.get());
      ASSERT_NE(hg, nullptr);
      RenderedFrame device, host, again;
      gpu->Render(snap, fx.get(), view, &device);
      const std::vector<cuda::StreakPod> device_pods = SplatPods(g);
      const int device_culled = g->realtime_frame().streaks_culled();
      const double device_ms = g->last_late_streaks_ms();
      const double queue_ms = g->device_drop_cull()->run_ms();
      host_gpu->Render(snap, fx.get(), view, &host);
      const std::vector<cuda::StreakPod> host_pods = SplatPods(hg);
      const int host_culled = hg->realtime_frame().streaks_culled();
      const double host_ms = hg->last_late_streaks_ms();
      EXPECT_EQ(hg->device_drop_cull(), nullptr);
      gpu->Render(snap, fx.get(), view, &again);
      const double again_ms = g->last_late_streaks_ms();
      std::printf(
          "%s 640x480%s%s: %zu streaks culled on the device, %zu on the host (the same: %s), rain "
          "culled %d / %d; late streaks on the host %.3f ms (device culling, the renderer's first "
          "frame; DeviceStreakCull::Queue %.3f ms of it) / %.3f ms (host) / %.3f ms (device "
          "culling, its second frame); frames bit-identical: %s\n",
          file, rolling ? ", rolling shutter" : "", k.fog ? ", in fog" : "", device_pods.size(),
          host_pods.size(), SamePods(device_pods, host_pods) ? "yes" : "NO", device_culled,
          host_culled, device_ms, queue_ms, host_ms, again_ms,
          device.radiance.data == host.radiance.data && device.rgb.data == host.rgb.data ? "yes"
                                                                                         : "NO");
      EXPECT_GT(host_pods.size(), 0u);
      EXPECT_TRUE(SamePods(device_pods, host_pods));
      EXPECT_EQ(device_culled, host_culled);
      if (std::string(file) == "effects/rain.yaml") {
        EXPECT_GT(host_culled, 0);
      }
      EXPECT_EQ(device.rgb.data, host.rgb.data);
      EXPECT_EQ(device.radiance.data, host.radiance.data);
      EXPECT_EQ(device.depth_m.data, host.depth_m.data);
      EXPECT_EQ(std::memcmp(&device.ev100, &host.ev100, sizeof(double)), 0);
      EXPECT_EQ(again.radiance.data, device.radiance.data);
      if (rolling) continue;
      // DeviceStreakCull alone on the frame's inputs: the same streaks; another exposure time
      // gives others
      const StreakCullSetup setup = g->realtime_frame().particles().cull_setup();
      const std::vector<cuda::DropSet> sets = cuda::DropSetsOf(*fx);
      cuda::DeviceStreakCull cull;
      cull.Run(sets.data(), static_cast<int32_t>(sets.size()), setup.frame, setup.sets.data());
      std::vector<cuda::StreakPod> alone;
      cull.Download(&alone);
      EXPECT_TRUE(SamePods(alone, host_pods));
      StreakCullFrame longer = setup.frame;
      longer.T *= 1.001f;
      cull.Run(sets.data(), static_cast<int32_t>(sets.size()), longer, setup.sets.data());
      cull.Download(&alone);
      EXPECT_FALSE(SamePods(alone, host_pods));
      // a non-finite drop: the host's error, naming it
      EffectsFrame bad = *fx;
      const size_t s = bad.particles.size() - 1;
      ASSERT_GT(bad.particles[s].position_W.size(), 7u);
      bad.particles[s].position_W[7].y() = std::numeric_limits<float>::quiet_NaN();
      const std::vector<cuda::DropSet> bad_sets = cuda::DropSetsOf(bad);
      try {
        cull.Run(bad_sets.data(), static_cast<int32_t>(bad_sets.size()), setup.frame,
                 setup.sets.data());
        ADD_FAILURE() << "no ConfigError for a non-finite drop";
      } catch (const ConfigError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("effects.particles[" + std::to_string(s) + "]"), std::string::npos)
            << what;
        EXPECT_NE(what.find("particle 7 has a non-finite value"), std::string::npos) << what;
      }
    }
  }
}

// the device culling's counts come back with the frame's outputs (Render queues the culling and
// the splat reads the streaks and their count on the device): a frame with a non-finite drop
// throws the host culling's ConfigError, naming the drop, from the same Render call, as the host
// culling does; the next clean frame is the clean frame of before to the bit, its culled rain
// the host culling's, and the device culling's streaks the host's.
TEST(StreakCullGpu, RenderThrowsTheHostCullingsErrorForANonFiniteDrop) {
  if (!ProbeCudaDevice().available) GTEST_SKIP() << "skipped: no CUDA device";
  auto [session, snap, view, loaded] =
      realtime_parity::LoadFrameAt("effects/rain.yaml", 1.0, 640, 480);
  ASSERT_TRUE(loaded && !loaded->particles.empty());
  EffectsFrame bad = *loaded;
  const size_t s = bad.particles.size() - 1;
  ASSERT_GT(bad.particles[s].position_W.size(), 7u);
  bad.particles[s].position_W[7].y() = std::numeric_limits<float>::quiet_NaN();
  const std::unique_ptr<Renderer> device_gpu = GpuRenderer(session->scene());
  const std::unique_ptr<Renderer> host_gpu = HostCullingRenderer(session->scene());
  RenderedFrame clean;
  host_gpu->Render(snap, loaded.get(), view, &clean);
  const int host_culled =
      dynamic_cast<cuda::CudaRenderer*>(host_gpu.get())->realtime_frame().streaks_culled();
  const std::vector<cuda::StreakPod> host_pods =
      SplatPods(dynamic_cast<cuda::CudaRenderer*>(host_gpu.get()));
  for (const bool device : {true, false}) {
    SCOPED_TRACE(std::string(device ? "device" : "host") + " culling");
    Renderer* gpu = device ? device_gpu.get() : host_gpu.get();
    auto* g = dynamic_cast<cuda::CudaRenderer*>(gpu);
    ASSERT_NE(g, nullptr);
    // the error's message ("" when none was thrown: both checks fail)
    const std::string what = [&] {
      RenderedFrame out;
      try {
        gpu->Render(snap, &bad, view, &out);
      } catch (const ConfigError& e) {
        return std::string(e.what());
      }
      return std::string();
    }();
    EXPECT_NE(what.find("effects.particles[" + std::to_string(s) + "]"), std::string::npos)
        << "message: '" << what << "'";
    EXPECT_NE(what.find("particle 7 has a non-finite value"), std::string::npos)
        << "message: '" << what << "'";
    RenderedFrame after;
    gpu->Render(snap, loaded.get(), view, &after);
    EXPECT_EQ(g->realtime_frame().streaks_culled(), host_culled);
    EXPECT_TRUE(SamePods(SplatPods(g), host_pods));
    EXPECT_EQ(after.rgb.data, clean.rgb.data);
    EXPECT_EQ(after.radiance.data, clean.radiance.data);
    EXPECT_EQ(std::memcmp(&after.ev100, &clean.ev100, sizeof(double)), 0);
  }
}

TEST(StreakCullGpu, SuccessiveFramesSendOnlyWhatChanged) {
  // frames 1/30 s apart: a rain drop keeps its velocity and radius, so after the first frame
  // only the positions (and the small parts) go over; snow drifts, so its velocities change and
  // everything goes over. every frame's streaks and image equal the host culling's.
  if (!ProbeCudaDevice().available) GTEST_SKIP() << "skipped: no CUDA device";
  for (const char* file : {"effects/rain.yaml", "effects/snow.yaml"}) {
    SCOPED_TRACE(file);
    auto [session, snap, view, loaded] = realtime_parity::LoadFrameAt(file, 1.0, 320, 240);
    ASSERT_TRUE(loaded && !loaded->particles.empty());
    const std::unique_ptr<Renderer> gpu = GpuRenderer(session->scene());
    auto* g = dynamic_cast<cuda::CudaRenderer*>(gpu.get());
    ASSERT_NE(g, nullptr);
    const std::unique_ptr<Renderer> host_gpu = HostCullingRenderer(session->scene());
    auto* hg = dynamic_cast<cuda::CudaRenderer*>(host_gpu.get());
    ASSERT_NE(hg, nullptr);
    size_t first_bytes = 0, later_bytes = 0;
    for (int frame = 0; frame < 3; ++frame) {
      if (frame > 0) {
        const double t = session->sim().time() + 1.0 / 30;
        while (session->sim().time() < t) session->sim().Step();
        snap = session->sim().Snapshot();
      }
      const std::shared_ptr<const EffectsFrame> fx =
          session->effects().Evaluate(snap, view.X_WO.translation());
      RenderedFrame device, host;
      gpu->Render(snap, fx.get(), view, &device);
      const std::vector<cuda::StreakPod> device_pods = SplatPods(g);
      const size_t bytes = g->device_drop_cull()->upload_bytes();
      host_gpu->Render(snap, fx.get(), view, &host);
      const std::vector<cuda::StreakPod> host_pods = SplatPods(hg);
      size_t drops = 0;
      for (const ParticleSet& ps : fx->particles) drops += ps.position_W.size();
      std::printf("%s frame %d: %zu drops, %zu bytes sent, %zu streaks, the same: %s\n", file,
                  frame, drops, bytes, device_pods.size(),
                  SamePods(device_pods, host_pods) ? "yes" : "NO");
      EXPECT_GT(host_pods.size(), 0u);
      EXPECT_TRUE(SamePods(device_pods, host_pods)) << frame;
      EXPECT_EQ(device.rgb.data, host.rgb.data) << frame;
      EXPECT_EQ(device.radiance.data, host.radiance.data) << frame;
      (frame == 0 ? first_bytes : later_bytes) = bytes;
      EXPECT_GE(bytes, sizeof(float) * 3 * drops);
    }
    if (std::string(file) == "effects/rain.yaml")
      EXPECT_LT(later_bytes, first_bytes * 6 / 10);
    else
      EXPECT_EQ(later_bytes, first_bytes);
  }
}

}  // namespace
}  // namespace penumbra
