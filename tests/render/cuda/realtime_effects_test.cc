// the lighting effects (light intensity scales, extra lights, the moved or scaled sky, surface
// wetness) on the CUDA backend's realtime rgb path, run on the CPU
// (RenderRealtimeOnHost: the PB_HOST_DEVICE functions the kernels run), against the CPU
// backend rendering the same EffectsFrame: the bundled worlds whose effects are only lighting
// (effects/blackout.yaml at 1 s and in its power cut at 4 s, effects/flashlight.yaml,
// effects/sun.yaml) and a hand-made frame with every lighting field set on the default room, at
// 160x120: rgb PSNR >= 40 dB, depth within 1 mm on >= 99.9 % of pixels, two renders
// bit-identical, and the effects change the image; the particle streaks of the rain and snow
// worlds (the media: realtime_media_test.cc). every effect is on the GPU.
// no GPU needed.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>

#include "host_path.h"
#include "penumbra/core/error.h"
#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/render/camera/camera.h"
#include "penumbra/render/cuda/cuda_renderer.h"
#include "penumbra/render/cuda/realtime_host.h"
#include "penumbra/render/frame/bvh_scene.h"
#include "penumbra/render/material/material_eval.h"
#include "penumbra/render/material/wetness_math.h"
#include "realtime_parity.h"

namespace penumbra {
namespace {

struct HostCompared {
  double psnr = 0, depth_bad = 1;
  RenderedFrame cpu, host, again;
};

// the CPU backend and the GPU path on the host for one scene at one snapshot, each built once
// (their sky irradiance volumes' builds are most of a frame's time here, the GPU path's
// through the host BVH), then any number of frames of `view` under any effects frame, as
// both renderers render frame after frame.
class HostAndCpu {
 public:
  HostAndCpu(const SceneDescription& scene, const WorldSnapshot& snap)
      : snap_(snap), cpu_(MakeRenderer(scene, Settings())), host_(scene, snap, Settings()) {}

  // both render `view` under `fx`; the GPU path twice.
  HostCompared Compare(const CameraView& view, const EffectsFrame* fx) {
    HostCompared c;
    cpu_->Render(snap_, fx, view, &c.cpu);
    c.host = host_.Render(view, fx);
    c.again = host_.Render(view, fx);
    c.psnr = realtime_parity::Psnr(c.cpu.rgb, c.host.rgb);
    c.depth_bad = realtime_parity::DepthMismatch(c.cpu.depth_m, c.host.depth_m);
    return c;
  }

  // the GPU path alone under fx without its particles.
  RenderedFrame RenderWithoutParticles(const CameraView& view, const EffectsFrame& fx) {
    EffectsFrame no_particles = fx;
    no_particles.particles.clear();
    return host_.Render(view, &no_particles);
  }

  cuda::RealtimeFrameData& data() { return host_.data(); }
  ThreadPool& pool() { return host_.pool(); }

 private:
  static RenderSettings Settings() {
    RenderSettings settings;
    settings.backend = RenderSettings::Backend::kEmbree;
    return settings;
  }

  const WorldSnapshot& snap_;
  std::unique_ptr<Renderer> cpu_;
  host_path::HostPath host_;
};

// the summed |radiance - CPU backend's| over the streak pixels `streaks` of the GPU path's frame
// (c.host: *err) and of its frame without the particles (`bare`: *bare_err).
void StreakPixelErrors(const std::vector<cuda::StreakPixel>& streaks, const HostCompared& c,
                       const RenderedFrame& bare, double* err, double* bare_err) {
  for (const cuda::StreakPixel& s : streaks)
    for (int k = 0; k < 3; ++k) {
      const int64_t i = 3 * s.pixel + k;
      *err += std::abs(c.cpu.radiance.data[i] - c.host.radiance.data[i]);
      *bare_err += std::abs(c.cpu.radiance.data[i] - bare.radiance.data[i]);
    }
}

// the streak pixels of the frame `data` was Prepared for, as the frame's splat keys them
// (SplatProjection, SplatStreakRow): each keyed pixel with its nearest streak's t and coverage,
// in pixel order.
std::vector<cuda::StreakPixel> SplatPixels(const cuda::RealtimeFrameData& data, int W, int H) {
  cuda::RealtimeFrameView f = data.View(cuda::SceneView(), nullptr);
  const cuda::PathStreaks& list = f.splat.streaks;
  std::vector<unsigned long long> nearest(static_cast<size_t>(W) * H, kNoStreakKey);
  f.splat.nearest = nearest.data();
  for (int k = 0; k < list.num; ++k) {
    const StreakProjection p = cuda::SplatProjection(f, list.streaks[k]);
    for (int v = p.v0; v <= p.v1 && !p.empty(); ++v) cuda::SplatStreakRow(f, k, p, v);
  }
  std::vector<cuda::StreakPixel> pixels;
  for (size_t i = 0; i < nearest.size(); ++i) {
    if (nearest[i] == kNoStreakKey) continue;
    cuda::StreakPixel s;
    s.pixel = static_cast<int64_t>(i);
    s.t = StreakKeyT(nearest[i]);
    s.alpha = list.streaks[StreakKeyIndex(nearest[i])].alpha;
    pixels.push_back(s);
  }
  return pixels;
}

struct HostEffectsWorld {
  const char* file;
  double t_sec;
};

class RealtimeHostPathEffects : public ::testing::TestWithParam<HostEffectsWorld> {};

TEST_P(RealtimeHostPathEffects, MatchesCpuBackend) {
  const HostEffectsWorld& w = GetParam();
  const auto [session, snap, view, fx] = realtime_parity::LoadFrameAt(w.file, w.t_sec, 160, 120);
  const SceneDescription& scene = session->scene();
  ASSERT_TRUE(fx && !fx->empty()) << w.file;
  HostAndCpu rig(scene, snap);
  const HostCompared c = rig.Compare(view, fx.get());
  // the clear frame of the same instant: the effects must change the GPU path's image.
  const HostCompared clear = rig.Compare(view, nullptr);
  std::printf(
      "%s at %.1f s 160x120: rgb PSNR %.2f dB (clear frame %.2f dB), ev100 cpu %.4f "
      "host-gpu-path %.4f (clear %.4f), depth > 1 mm on %.4f %% of pixels\n",
      w.file, w.t_sec, c.psnr, clear.psnr, c.cpu.ev100, c.host.ev100, clear.host.ev100,
      100 * c.depth_bad);
  EXPECT_GE(c.psnr, 40.0) << w.file;
  EXPECT_LE(c.depth_bad, 0.001) << w.file;
  EXPECT_EQ(c.host.rgb.data, c.again.rgb.data) << w.file;
  EXPECT_EQ(c.host.radiance.data, c.again.radiance.data) << w.file;
  EXPECT_NE(c.host.radiance.data, clear.host.radiance.data) << w.file;
}

INSTANTIATE_TEST_SUITE_P(Bundled, RealtimeHostPathEffects,
                         ::testing::Values(HostEffectsWorld{"effects/blackout.yaml", 1.0},
                                           HostEffectsWorld{"effects/blackout.yaml", 4.0},
                                           HostEffectsWorld{"effects/flashlight.yaml", 1.0},
                                           HostEffectsWorld{"effects/sun.yaml", 1.0}));

// the particles of the rain and snow worlds at 1 s (the rover's camera, 160x120; rain also
// wets the ground): the streaks splatted and shaded by the frame itself (StreakSplatView) give
// the CPU backend's image (PSNR >= 40 dB); on the streaks' pixels (SplatPixels) the GPU path
// without them is far from it.
TEST(RealtimeHostPathEffectsFrames, ParticleStreaksMatchCpuBackend) {
  for (const char* file : {"effects/rain.yaml", "effects/snow.yaml"}) {
    SCOPED_TRACE(file);
    const auto [session, snap, view, fx] = realtime_parity::LoadFrameAt(file, 1.0, 160, 120);
    const SceneDescription& scene = session->scene();
    ASSERT_TRUE(fx && !fx->particles.empty());
    HostAndCpu rig(scene, snap);
    const HostCompared c = rig.Compare(view, fx.get());
    const RenderedFrame bare = rig.RenderWithoutParticles(view, *fx);
    // the streak pixels of the frame
    cuda::RealtimeFrameData& data = rig.data();
    data.Prepare(snap, view, &rig.pool(), fx.get());
    const std::vector<cuda::StreakPixel> streaks =
        SplatPixels(data, view.intrinsics.width, view.intrinsics.height);
    double err = 0, bare_err = 0;
    StreakPixelErrors(streaks, c, bare, &err, &bare_err);
    std::printf(
        "%s at 1 s 160x120: %zu streak pixels, rgb PSNR %.2f dB (without the streaks %.2f dB), "
        "mean |radiance - cpu| on them %.4g (without %.4g) cd/m^2, depth > 1 mm on %.4f %%\n",
        file, streaks.size(), c.psnr, realtime_parity::Psnr(c.cpu.rgb, bare.rgb),
        err / std::max<size_t>(1, 3 * streaks.size()),
        bare_err / std::max<size_t>(1, 3 * streaks.size()), 100 * c.depth_bad);
    EXPECT_GT(streaks.size(), 50u);
    EXPECT_GE(c.psnr, 40.0);
    EXPECT_LE(c.depth_bad, 0.001);
    EXPECT_LT(err, 0.1 * bare_err);
    EXPECT_EQ(c.host.rgb.data, c.again.rgb.data);
  }
}

// the realtime particle streaks splatted and shaded by the frame itself (StreakSplatView, here
// on the CPU by RenderRealtimeOnHost, the kernels' functions): rain and snow (the rover's camera,
// shelter and rain culling) and fire (sparks seen through the fire's grid media: MediaViewQuad)
// at 1 s, 160x120. the splat keys streak pixels, two renders are bit-identical and the frame
// without its particles differs on some pixels.
TEST(RealtimeHostPathEffectsFrames, FrameSplatDrawsTheStreaksWithTheSameBitsTwice) {
  for (const char* file : {"effects/rain.yaml", "effects/snow.yaml", "effects/fire.yaml"}) {
    SCOPED_TRACE(file);
    const auto [session, snap, view, fx] = realtime_parity::LoadFrameAt(file, 1.0, 160, 120);
    const SceneDescription& scene = session->scene();
    ASSERT_TRUE(fx && !fx->particles.empty());
    cuda::BvhScene bvh(scene);
    bvh.Update(snap);
    ThreadPool pool(0);
    cuda::RealtimeFrameData data(scene, RenderSettings());
    RenderedFrame device, again, bare;
    data.Prepare(snap, view, &pool, fx.get());
    cuda::RenderRealtimeOnHost(data, bvh, &pool, &device, /*stored_surface=*/true);
    cuda::RenderRealtimeOnHost(data, bvh, &pool, &again, /*stored_surface=*/true);
    const int num = data.splat_streaks().View().num;
    const size_t keyed = SplatPixels(data, view.intrinsics.width, view.intrinsics.height).size();
    EffectsFrame no_particles = *fx;
    no_particles.particles.clear();
    data.Prepare(snap, view, &pool, &no_particles);
    cuda::RenderRealtimeOnHost(data, bvh, &pool, &bare, /*stored_surface=*/true);
    int64_t changed = 0;
    for (size_t i = 0; i < bare.radiance.data.size(); i += 3)
      changed += std::memcmp(&bare.radiance.data[i], &device.radiance.data[i], 12) != 0 ? 1 : 0;
    std::printf(
        "%s at 1 s 160x120: %d streaks after the host's culling, %zu streak pixels; rgb PSNR "
        "without the particles %.2f dB (%lld pixels' radiance changed by them)\n",
        file, num, keyed, realtime_parity::Psnr(device.rgb, bare.rgb),
        static_cast<long long>(changed));
    EXPECT_GT(num, 0);
    EXPECT_GT(keyed, 0u);
    EXPECT_EQ(device.rgb.data, again.rgb.data);
    EXPECT_EQ(device.radiance.data, again.radiance.data);
    EXPECT_EQ(device.depth_m.data, again.depth_m.data);
    EXPECT_GT(changed, 0);
  }
}

// the late streaks (CudaRenderer makes the frame's streaks while the GPU shades):
// Prepare without streaks, then PrepareStreaks after the media, gives the frame of a Prepare
// with them to the bit (rgb, radiance, depth, EV100), rain and snow (the rover's camera,
// shelter and rain culling) and fire (sparks through the fire's grid media, which PrepareMedia
// builds before the late streaks) at 1 s, 160x120, after a frame of other streaks; the frame
// in between, without streaks, has none of the earlier frame's (so the comparison can fail:
// its image differs), and StreakFields sets what View sets.
TEST(RealtimeHostPathEffectsFrames, LateStreaksGiveTheSameBits) {
  for (const char* file : {"effects/rain.yaml", "effects/snow.yaml", "effects/fire.yaml"}) {
    SCOPED_TRACE(file);
    const auto [session, snap, view, fx] = realtime_parity::LoadFrameAt(file, 1.0, 160, 120);
    ASSERT_TRUE(fx && !fx->particles.empty());
    host_path::HostPath path(session->scene(), snap);
    cuda::RealtimeFrameData& data = path.data();
    const cuda::BvhScene& bvh = path.bvh();
    ThreadPool& pool = path.pool();
    RenderedFrame late, none;
    const RenderedFrame serial = path.Render(view, fx.get());
    const int num = data.splat_streaks().View().num;
    // without streaks: the last frame's are gone
    data.Prepare(snap, view, &pool, fx.get(), nullptr, nullptr, /*streaks=*/false);
    const cuda::RealtimeFrameView bare = data.View(bvh.view(), nullptr);
    EXPECT_EQ(bare.splat.streaks.num, 0);
    cuda::RenderRealtimeOnHost(data, bvh, &pool, &none, /*stored_surface=*/true);
    // then late, after PrepareMedia, as CudaRenderer's late streaks
    const Camera camera(view.X_WO, view.intrinsics, view.motion);
    data.PrepareStreaks(snap, fx.get(), camera, view, &pool);
    cuda::RenderRealtimeOnHost(data, bvh, &pool, &late, /*stored_surface=*/true);
    const cuda::RealtimeFrameView v = data.View(bvh.view(), nullptr);
    cuda::RealtimeFrameView fields;
    data.StreakFields(&fields);
    EXPECT_EQ(fields.splat.streaks.num, v.splat.streaks.num);
    EXPECT_EQ(fields.splat.streaks.streaks, v.splat.streaks.streaks);
    EXPECT_EQ(std::memcmp(fields.splat.R_OW, v.splat.R_OW, sizeof(v.splat.R_OW)), 0);
    int64_t changed = 0;
    for (size_t i = 0; i < none.radiance.data.size(); i += 3)
      changed += std::memcmp(&none.radiance.data[i], &serial.radiance.data[i], 12) != 0 ? 1 : 0;
    std::printf(
        "%s at 1 s 160x120: %d streaks, made in Prepare and late: the same bits %s; the frame "
        "without them differs in %lld pixels' radiance\n",
        file, num, late.radiance.data == serial.radiance.data ? "yes" : "NO",
        static_cast<long long>(changed));
    EXPECT_GT(num, 0);
    EXPECT_EQ(v.splat.streaks.num, num);
    EXPECT_EQ(late.rgb.data, serial.rgb.data);
    EXPECT_EQ(late.radiance.data, serial.radiance.data);
    EXPECT_EQ(late.depth_m.data, serial.depth_m.data);
    EXPECT_EQ(std::memcmp(&late.ev100, &serial.ev100, sizeof(double)), 0);
    EXPECT_GT(changed, 0);
  }
}

// a moving camera with a rolling shutter (realtime_parity::AddRollingShutter) in the rain world
// at 1 s, 160x120, through the frame's splat (here on the CPU): the splat's rays are the CPU's
// Camera::GenerateRay to the bit (SplatRay over the rows' double poses, StreakSplatView::rows),
// and its keys equal a brute force over every pixel's ray and every streak (the boxes widened by
// the rows' motion, each row's columns in its own pose); with the camera's float ray tables
// instead (PrimaryRay<true>), the still camera's rays or the first row's pose only
// (StreakSplatView::poses null) they differ (the check can fail). the frame matches the CPU
// backend's (rgb PSNR >= 40 dB, depth within 1 mm on >= 99.9 % of pixels, the streak pixels'
// radiance within a tenth of their error without the streaks).
TEST(RealtimeHostPathEffectsFrames, RollingShutterDeviceSplatMatchesCpuBackend) {
  auto [session, snap, view, fx] = realtime_parity::LoadFrameAt("effects/rain.yaml", 1.0, 160, 120);
  const SceneDescription& scene = session->scene();
  ASSERT_TRUE(fx && !fx->particles.empty());
  realtime_parity::AddRollingShutter(&view);
  ASSERT_TRUE(view.motion.moving());
  HostAndCpu rig(scene, snap);
  const HostCompared c = rig.Compare(view, fx.get());
  const RenderedFrame bare = rig.RenderWithoutParticles(view, *fx);
  // the splat's keys with the frame's rays (the row table) and with the still camera's
  cuda::RealtimeFrameData& data = rig.data();
  data.Prepare(snap, view, &rig.pool(), fx.get());
  const int W = view.intrinsics.width, H = view.intrinsics.height;
  cuda::RealtimeFrameView f = data.View(cuda::SceneView(), nullptr);
  ASSERT_NE(f.camera.rows, nullptr);
  const cuda::PathStreaks& list = f.splat.streaks;
  ASSERT_GT(list.num, 0);
  const auto splat_keys = [&](const cuda::RealtimeFrameView& fv) {
    std::vector<unsigned long long> keys(static_cast<size_t>(W) * H, kNoStreakKey);
    cuda::RealtimeFrameView g = fv;
    g.splat.nearest = keys.data();
    for (int k = 0; k < list.num; ++k) {
      const StreakProjection p = cuda::SplatProjection(g, list.streaks[k]);
      for (int v = p.v0; v <= p.v1 && !p.empty(); ++v) cuda::SplatStreakRow(g, k, p, v);
    }
    return keys;
  };
  ASSERT_NE(f.splat.rows, nullptr);
  ASSERT_NE(f.splat.poses, nullptr);
  const std::vector<unsigned long long> keys = splat_keys(f);
  // every pixel's nearest streak by brute force (each pixel's ray, SplatRay, against every
  // streak): the splat's keys exactly; the splat with the first row's pose only (no
  // StreakSplatView::poses: its boxes and row columns of the first row's pose) misses some
  std::vector<unsigned long long> brute(static_cast<size_t>(W) * H, kNoStreakKey);
  for (int v = 0; v < H; ++v) {
    for (int u = 0; u < W; ++u) {
      const cuda::TraceRay ray = cuda::SplatRay(f, u, v);
      unsigned long long& slot = brute[static_cast<size_t>(v) * W + u];
      for (int k = 0; k < list.num; ++k) {
        const cuda::StreakPod& s = list.streaks[k];
        const float t = IntersectCapsuleRay(
            MakeCapsuleOrigin(cuda::ToFloat3(ray.o), Float3{s.a[0], s.a[1], s.a[2]},
                              Float3{s.b[0], s.b[1], s.b[2]}, s.r),
            cuda::ToFloat3(ray.d));
        if (t > 0) slot = std::min<unsigned long long>(slot, StreakKey(t, k));
      }
    }
  }
  cuda::RealtimeFrameView first_pose = f;
  first_pose.splat.poses = nullptr;
  const std::vector<unsigned long long> first_keys = splat_keys(first_pose);
  size_t brute_keyed = 0, brute_differ = 0, first_differ = 0;
  for (size_t i = 0; i < brute.size(); ++i) {
    brute_keyed += brute[i] != kNoStreakKey ? 1 : 0;
    brute_differ += brute[i] != keys[i] ? 1 : 0;
    first_differ += brute[i] != first_keys[i] ? 1 : 0;
  }
  std::printf(
      "rain at 1 s 160x120, rolling shutter: brute force keys %zu pixels; the splat differs on "
      "%zu, with the first row's pose only on %zu\n",
      brute_keyed, brute_differ, first_differ);
  // how many pixels' keys differ from the brute force's
  const auto differ = [&](const std::vector<unsigned long long>& k) {
    size_t n = 0;
    for (size_t i = 0; i < brute.size(); ++i) n += brute[i] != k[i] ? 1 : 0;
    return n;
  };
  EXPECT_GT(brute_keyed, 50u);
  EXPECT_EQ(brute_differ, 0u);
  EXPECT_GT(first_differ, brute_keyed / 4);
  // the frame's float ray tables instead of the double row poses (float rays), and
  // the still camera's rays
  cuda::RealtimeFrameView tables = f;
  tables.splat.rows = nullptr;
  const size_t bad_float = differ(splat_keys(tables));
  cuda::RealtimeFrameView still = tables;
  still.camera.rows = nullptr;
  const size_t bad_still = differ(splat_keys(still));
  const std::vector<cuda::StreakPixel> pixels = SplatPixels(data, W, H);
  double err = 0, bare_err = 0;
  StreakPixelErrors(pixels, c, bare, &err, &bare_err);
  std::printf(
      "rain at 1 s 160x120, rolling shutter: %d streaks, %zu streak pixels, %zu keys not the brute "
      "force's with the float ray tables, %zu with the still camera's rays; rgb PSNR against the "
      "CPU backend %.2f dB (without the streaks %.2f dB), mean |radiance - cpu| on the streak "
      "pixels %.4g (without %.4g) cd/m^2, depth > 1 mm on %.4f %%\n",
      list.num, pixels.size(), bad_float, bad_still, c.psnr,
      realtime_parity::Psnr(c.cpu.rgb, bare.rgb), err / std::max<size_t>(1, 3 * pixels.size()),
      bare_err / std::max<size_t>(1, 3 * pixels.size()), 100 * c.depth_bad);
  EXPECT_EQ(pixels.size(), brute_keyed);
  EXPECT_GT(bad_float, 0u);
  EXPECT_GT(bad_still, 0u);
  EXPECT_EQ(c.host.rgb.data, c.again.rgb.data);
  EXPECT_GE(c.psnr, 40.0);
  EXPECT_LE(c.depth_bad, 0.001);
  EXPECT_LT(err, 0.1 * bare_err);
}

// every lighting field at once on the default room (its window lets the sun and sky in): a
// lamp scaled, the sun moved and the sky dimmed, a spot light added, the floor wet.
TEST(RealtimeHostPathEffectsFrames, EveryLightingFieldMatchesCpuBackend) {
  const std::unique_ptr<Session> session = realtime_parity::LoadSimulatedAt("default.yaml", 1.0);
  const SceneDescription& scene = session->scene();
  const WorldSnapshot snap = session->sim().Snapshot();
  const CameraView view = realtime_parity::RgbDepthView(scene, snap, 160, 120);
  EffectsFrame fx;
  fx.light_intensity_scale.assign(scene.lights.size(), 0.5f);
  fx.sun_direction_W = Eigen::Vector3d(0.3, -0.5, 0.6);
  fx.sky_luminance_scale = 0.4f;
  fx.surface_wetness = 0.8f;
  Light spot;
  spot.type = Light::Type::kSpot;
  spot.position_B = view.X_WO.translation() + Eigen::Vector3d(0, 0, 0.2);
  spot.direction_B = view.X_WO.linear().col(2);
  spot.intensity = 300;
  spot.spot_inner_deg = 15;
  spot.spot_outer_deg = 30;
  fx.extra_lights.push_back(spot);
  HostAndCpu rig(scene, snap);
  const HostCompared c = rig.Compare(view, &fx);
  const HostCompared clear = rig.Compare(view, nullptr);
  std::printf("default + every lighting field 160x120: rgb PSNR %.2f dB, ev100 cpu %.4f / %.4f\n",
              c.psnr, c.cpu.ev100, c.host.ev100);
  EXPECT_GE(c.psnr, 40.0);
  EXPECT_LE(c.depth_bad, 0.001);
  EXPECT_EQ(c.host.rgb.data, c.again.rgb.data);
  EXPECT_NE(c.host.radiance.data, clear.host.radiance.data);
  // out of range, as the CPU backend: a ConfigError naming the key.
  fx.surface_wetness = 1.5f;
  EXPECT_THROW(rig.data().Prepare(snap, view, &rig.pool(), &fx), ConfigError);
  fx.surface_wetness = 0;
  fx.sky_luminance_scale = -1;
  EXPECT_THROW(rig.data().Prepare(snap, view, &rig.pool(), &fx), ConfigError);
}

// the shared wetness formula: dry where the surface is vertical or faces down, albedo x 0.3 and
// gloss x 2.5 (capped) fully wet facing up, metals keep their albedo; ApplySurfaceWetness (the
// CPU's) is it.
TEST(RealtimeHostPathEffectsFrames, SharedWetnessFormula) {
  float scale = -1, rough = -1;
  EXPECT_FALSE(SurfaceWetnessTerms(1.0f, 0.0f, 0.0f, 0.5f, &scale, &rough));
  EXPECT_FALSE(SurfaceWetnessTerms(1.0f, -1.0f, 0.0f, 0.5f, &scale, &rough));
  EXPECT_FALSE(SurfaceWetnessTerms(0.0f, 1.0f, 0.0f, 0.5f, &scale, &rough));
  ASSERT_TRUE(SurfaceWetnessTerms(1.0f, 1.0f, 0.0f, 0.8f, &scale, &rough));
  EXPECT_FLOAT_EQ(scale, 0.3f);
  EXPECT_FLOAT_EQ(rough, 1.0f - 0.2f * 2.5f);
  ASSERT_TRUE(SurfaceWetnessTerms(1.0f, 1.0f, 1.0f, 0.2f, &scale, &rough));
  EXPECT_FLOAT_EQ(scale, 1.0f);
  EXPECT_FLOAT_EQ(rough, 0.0f);
  PbrParams pbr;
  pbr.base_color = Eigen::Vector3f(0.5f, 0.25f, 1.0f);
  pbr.roughness = 0.6f;
  ApplySurfaceWetness(0.7f, Eigen::Vector3f(0, 0.6f, 0.8f), &pbr);
  ASSERT_TRUE(SurfaceWetnessTerms(0.7f, 0.8f, 0.0f, 0.6f, &scale, &rough));
  EXPECT_EQ(pbr.base_color.x(), 0.5f * scale);
  EXPECT_EQ(pbr.base_color.y(), 0.25f * scale);
  EXPECT_EQ(pbr.roughness, rough);
}

}  // namespace
}  // namespace penumbra
