// the pathtraced tier's one chain (render/transport/path_trace.h) traced over the GPU's ray
// tracer on the CPU (TraceOverBvh: PathTracePixel with BvhTracer, the host BVH), against the CPU
// backend (the same chain over Embree, render/cpu/path_tiles.h) on the bundled default and house
// worlds (lamp spheres, the sun disc through the window, the daylight sky) at 64x48 and 16
// samples per pixel, no denoiser: the radiance's mean relative difference at the scale of 8x8
// blocks (path_parity.h) within kHostTileTolerance, and two renders bit-identical: the tracer
// seam alone. dropping the sky or the lights from the frame moves it far beyond that (the metric
// can fail). no GPU needed.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <utility>

#include "path_parity.h"
#include "penumbra/core/rng.h"
#include "penumbra/core/thread_pool.h"
#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/render/bvh/bvh_traversal.h"
#include "penumbra/render/camera/camera.h"
#include "penumbra/render/frame/bvh_scene.h"
#include "penumbra/render/frame/camera_rays.h"
#include "penumbra/render/frame/path_frame.h"
#include "penumbra/render/light/emitter_sampler.h"
#include "penumbra/render/media/media_scene.h"
#include "penumbra/render/particles/particle_math.h"
#include "penumbra/render/transport/path_streaks.h"
#include "penumbra/render/transport/path_trace.h"
#include "realtime_parity.h"

namespace penumbra {
namespace {

// the two tracers feed the one chain with the CPU's random streams and rounding: what differs
// is where the BVH and Embree round a hit's distance and barycentrics, after which a path may
// branch differently. the bound is 1 % (docs/journal/2026-11-29-path-cpu.md).
constexpr double kHostTileTolerance = 0.01;

// the paths of frame `pf` (host arrays) traced over the host BVH (BvhTracer, as the GPU traces
// them), rows over `pool`, into *out.
void TraceOverBvh(const cuda::PathFrameView& frame, ThreadPool* pool, cuda::PathBuffers* out) {
  const int W = frame.rt.camera.width, H = frame.rt.camera.height;
  out->Resize(static_cast<int64_t>(W) * H);
  cuda::PathFrameView pf = frame;
  pf.radiance = out->radiance.data();
  pf.albedo = out->albedo.data();
  pf.normal = out->normal.data();
  pf.depth = out->depth.data();
  const auto go_on = [] { return false; };
  ParallelForOrSerial(pool, H, [&](int64_t v) {
    for (int u = 0; u < W; ++u)
      cuda::PathTracePixel(pf, cuda::BvhTracer{pf.rt.scene}, u, static_cast<int>(v), go_on);
  });
}

struct HostPathtraced {
  RenderedFrame want;
  cuda::PathBuffers got, again, no_sky, no_lights;
  int W = 0, H = 0;
};

// `distorted`: the camera with lens distortion and a rolling shutter over a moving, turning
// camera (path_parity::DistortAndMove)
HostPathtraced RenderBoth(const std::string& world, bool distorted = false) {
  const std::unique_ptr<Session> session = realtime_parity::LoadSimulated(world);
  const SceneDescription& scene = session->scene();
  const WorldSnapshot snap = session->sim().Snapshot();
  CameraView view = realtime_parity::RgbDepthView(scene, snap, 64, 48);
  if (distorted) path_parity::DistortAndMove(&view);
  const RenderSettings settings = path_parity::PathSettings(RenderSettings::Backend::kEmbree, 16);
  HostPathtraced r;
  r.W = 64, r.H = 48;
  MakeRenderer(scene, settings)->Render(snap, view, &r.want);
  cuda::BvhScene bvh(scene);
  bvh.Update(snap);
  cuda::RealtimeFrameData data(scene, settings);
  ThreadPool pool(0);
  // the bundled worlds have no emissive geom
  EXPECT_TRUE(EmitterSampler(scene).empty());
  data.Prepare(snap, view, &pool);
  const cuda::PathFrameView pf =
      cuda::PathView(data, data.View(bvh.view(), nullptr), data.frame_sky().sampling_pod());
  TraceOverBvh(pf, &pool, &r.got);
  TraceOverBvh(pf, &pool, &r.again);
  cuda::PathFrameView dropped = pf;
  dropped.sky_active = 0;
  TraceOverBvh(dropped, &pool, &r.no_sky);
  dropped = pf;
  dropped.rt.num_lights = 0;
  TraceOverBvh(dropped, &pool, &r.no_lights);
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

// a camera with lens distortion and a rolling shutter over a moving, turning camera: the host path
// traces its jittered rays from the ray tables (JitteredCameraRay), the CPU undistorts and poses
// each one exactly; the estimates agree as above (1 %), and differ from the same camera's
// undistorted, unmoving frame (so the tables are used).
TEST(PathtracedHostPath, DistortedMovingCameraTracksTheCpuBackendsEstimate) {
  const HostPathtraced r = RenderBoth("default.yaml", true);
  const HostPathtraced plain = RenderBoth("default.yaml", false);
  const ImageF got = RadianceOf(r.got, r.W, r.H);
  const double tile = path_parity::TileRelativeDifference(got, r.want.radiance);
  const double mean = path_parity::MeanRelativeDifference(got, r.want.radiance);
  const double vs_plain =
      path_parity::TileRelativeDifference(RadianceOf(plain.got, r.W, r.H), r.want.radiance);
  std::printf(
      "default.yaml distorted and moving 64x48 16 spp: radiance mean relative difference %.4f %% "
      "(8x8 blocks), %.4f %% (image mean); the plain camera's frame %.2f %%\n",
      100 * tile, 100 * mean, 100 * vs_plain);
  EXPECT_LE(tile, kHostTileTolerance);
  EXPECT_GT(vs_plain, kHostTileTolerance);
  EXPECT_EQ(0, std::memcmp(r.got.radiance.data(), r.again.radiance.data(),
                           sizeof(Float3) * r.got.radiance.size()));
}

// JitteredCameraRay against Camera::GenerateRay at the same continuous pixel positions: the
// pinhole exactly (its closed form, up to float rounding), a camera with lens distortion and a
// rolling shutter through its ray tables within the linear interpolation's second-order error,
// which falls with the square of the pixel's angle (measured: the numbers printed).
TEST(JitteredCameraRay, FollowsCameraGenerateRay) {
  for (const int w : {64, 640}) {
    const int h = w * 3 / 4;
    CameraView view;
    view.intrinsics = CameraIntrinsics::FromFovy(w, h, 70.0);
    view.X_WO.translation() = Eigen::Vector3d(0.3, -1.0, 1.2);
    view.X_WO.linear() =
        Eigen::AngleAxisd(0.4, Eigen::Vector3d(0.2, 1.0, 0.1).normalized()).matrix();
    CameraView moving = view;
    path_parity::DistortAndMove(&moving);
    const double pixel_rad = 70.0 * M_PI / 180.0 / h;
    ThreadPool pool(0);
    for (const CameraView* cv : {&view, &moving}) {
      cuda::CameraRayTables tables;
      tables.Prepare(*cv, &pool);
      const cuda::PinholeCamera c =
          tables.Point(cuda::PinholeCameraOf(*cv), tables.xy().data(), tables.rows().data());
      const Camera camera(cv->X_WO, cv->intrinsics, cv->motion);
      double worst_angle = 0, worst_origin = 0;
      Rng rng(7);
      for (int k = 0; k < 20000; ++k) {
        const int u = std::min(w - 1, static_cast<int>(rng.Uniform() * w));
        const int v = std::min(h - 1, static_cast<int>(rng.Uniform() * h));
        const float jx = rng.Uniform(), jy = rng.Uniform();
        const cuda::TraceRay r = cuda::JitteredCameraRay(c, u, v, jx, jy);
        const Ray want = camera.GenerateRay(static_cast<float>(u) + jx - 0.5f,
                                            static_cast<float>(v) + jy - 0.5f);
        const Eigen::Vector3d d(r.d.x, r.d.y, r.d.z), o(r.o.x, r.o.y, r.o.z);
        const Eigen::Vector3d wd = want.d.cast<double>(), wo = want.o.cast<double>();
        worst_angle =
            std::max(worst_angle, std::acos(std::min(1.0, d.normalized().dot(wd.normalized()))));
        worst_origin = std::max(worst_origin, (o - wo).norm());
      }
      const bool pinhole = cv == &view;
      std::printf("%dx%d %s: worst angle %.3g rad (%.3g of a pixel), worst origin %.3g m\n", w, h,
                  pinhole ? "pinhole" : "distorted, rolling shutter", worst_angle,
                  worst_angle / pixel_rad, worst_origin);
      // a pinhole: float rounding; the tables: the interpolation, measured 0.021 of a pixel at
      // 64x48 and 0.0020 at 640x480 (in radians 100 times less: the square of the pixel)
      EXPECT_LT(worst_angle / pixel_rad, pinhole ? 1e-4 : (w == 64 ? 0.05 : 0.005));
      EXPECT_LT(worst_origin, 1e-5);
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

// a MediaFrameCase's pathtraced frame (16 spp, 4 bounces, no denoiser) on the CPU backend (want)
// and as the GPU path takes it on the host (pf: the host BVH, the frame data Prepared with the
// effects without media, the media's own MediaScene; no streaks set), `pool` all cores.
struct EffectsPathFrame {
  RenderedFrame want;
  std::unique_ptr<cuda::BvhScene> bvh;
  std::unique_ptr<cuda::RealtimeFrameData> data;
  EffectsFrame storage;
  MediaScene media;
  cuda::PathFrameView pf;
};

void PrepareEffectsPath(const MediaFrameCase& c, ThreadPool* pool, EffectsPathFrame* e) {
  const SceneDescription& scene = c.session->scene();
  const RenderSettings settings = path_parity::PathSettings(RenderSettings::Backend::kEmbree, 16);
  MakeRenderer(scene, settings)->Render(c.snap, c.fx.get(), c.view, &e->want);
  e->bvh = std::make_unique<cuda::BvhScene>(scene);
  e->bvh->Update(c.snap);
  e->data = std::make_unique<cuda::RealtimeFrameData>(scene, settings);
  e->data->Prepare(c.snap, c.view, pool, cuda::EffectsWithoutMedia(c.fx.get(), &e->storage));
  e->media.Build(c.fx.get());
  e->pf = cuda::PathView(*e->data, e->data->View(e->bvh->view(), nullptr),
                         e->data->frame_sky().sampling_pod());
  e->pf.media = e->media.View();
}

// the GPU path with media (TracePath<true>: the free flights' delta tracking, the phase
// function's next events and samples, the media's transmittance on every shadow ray; the shared
// formulas of render/media/media_scene_math.h), run on the CPU over the BVH, against the CPU
// backend (the chain over Embree): fog (homogeneous; the rover's camera) and smoke_plume (a grid;
// the overview camera, which sees the plume), 64x48, 16 spp. the paths draw the CPU's random
// numbers, so they track its estimate closely; without the media (the paths of clear air) the
// difference is far larger (the metric can fail).
class PathtracedHostMedia : public ::testing::TestWithParam<std::pair<std::string, int>> {};

TEST_P(PathtracedHostMedia, TracksTheCpuBackendsEstimate) {
  const std::string world = GetParam().first;
  const MediaFrameCase c = LoadMediaFrame(world, GetParam().second, 64, 48);
  ASSERT_TRUE(c.fx);
  ASSERT_FALSE(c.fx->homogeneous_media.empty() && c.fx->grid_media.empty());
  ThreadPool pool(0);
  EffectsPathFrame e;
  PrepareEffectsPath(c, &pool, &e);
  EXPECT_FALSE(e.data->has_media());  // the realtime tier's media volumes are not built
  const RenderedFrame& want = e.want;
  const MediaScene& media = e.media;
  cuda::PathFrameView pf = e.pf;
  cuda::PathBuffers got, again, clear;
  TraceOverBvh(pf, &pool, &got);
  TraceOverBvh(pf, &pool, &again);
  pf.media = MediaSceneView();
  TraceOverBvh(pf, &pool, &clear);
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

// the GPU path with particles (TracePath<..., true>: a camera ray that meets a streak of the
// frame's BVH (path_streaks.h) stops there with probability alpha, one draw, before the media's
// free flight, and adds the streak's radiance, ShadeStreak), run on the CPU over the BVH, against
// the CPU backend (the chain over Embree): rain and snow (the rover's camera) and fire
// (sparks over a fire grid: TracePath<true, true>; the overview camera) at 1 s, 64x48, 16 spp.
// the paths draw the CPU's random numbers, so the estimates agree closely; the same paths without
// the streaks differ by far more (the metric can fail). the streaks' BVH is checked against a
// test of every streak (same nearest streak and t, bit for bit) on the camera's rays, and its
// host build time is printed.
// the streaks change these 64x48 frames by 0.23 % (fire's few sparks) to 0.80 % (snow) at the
// block scale, below the 1 % of the GPU tests: the tolerance here is the host path's own, 0.05 %
// (both trace the streaks with the capsule BVH and draw the same random numbers, so only where
// Embree and the BVH round a surface hit apart do the paths differ), which the same paths
// without the streaks exceed four times over.
constexpr double kHostParticleTolerance = 0.0005;

class PathtracedHostParticles : public ::testing::TestWithParam<std::pair<std::string, int>> {};

TEST_P(PathtracedHostParticles, TracksTheCpuBackendsEstimate) {
  const std::string world = GetParam().first;
  const MediaFrameCase c = LoadMediaFrame(world, GetParam().second, 64, 48);
  ASSERT_TRUE(c.fx);
  ASSERT_FALSE(c.fx->particles.empty());
  ThreadPool pool(0);
  EffectsPathFrame e;
  PrepareEffectsPath(c, &pool, &e);
  const cuda::RealtimeFrameData& data = *e.data;
  EXPECT_EQ(data.splat_streaks().View().num, 0);  // no realtime splat streaks for the paths
  const cuda::PathStreaks streaks = data.path_streaks().View();
  ASSERT_GT(streaks.num, 0);
  const RenderedFrame& want = e.want;
  cuda::PathFrameView pf = e.pf;
  pf.streaks = streaks;
  cuda::PathBuffers got, again, clear;
  TraceOverBvh(pf, &pool, &got);
  TraceOverBvh(pf, &pool, &again);
  pf.streaks = cuda::PathStreaks();
  TraceOverBvh(pf, &pool, &clear);
  const double tile = path_parity::TileRelativeDifference(RadianceOf(got, 64, 48), want.radiance);
  const double mean = path_parity::MeanRelativeDifference(RadianceOf(got, 64, 48), want.radiance);
  const double tile_clear =
      path_parity::TileRelativeDifference(RadianceOf(clear, 64, 48), want.radiance);
  // the BVH against every streak on 64x48x4 jittered camera rays
  const Camera camera(c.view.X_WO, c.view.intrinsics, c.view.motion);
  Rng rng(35);
  int hits = 0;
  for (int i = 0; i < 64 * 48 * 4; ++i) {
    const Ray ray = camera.GenerateRay(64 * rng.Uniform() - 0.5f, 48 * rng.Uniform() - 0.5f);
    const Float3 o{ray.o.x(), ray.o.y(), ray.o.z()}, d{ray.d.x(), ray.d.y(), ray.d.z()};
    float t = 0;
    int k = -1;
    const bool hit = cuda::PathStreakHit(streaks, o, d, 0.0f, INFINITY, &t, &k);
    // every streak: the nearest hit in [0, inf), ties to the first in leaf order
    const float len = std::sqrt(EigenDot(d, d));
    const Float3 du{d.x / len, d.y / len, d.z / len};
    float best_t = INFINITY;
    int best = -1;
    for (int j = 0; j < streaks.num; ++j) {
      const cuda::StreakPod& sp = streaks.streaks[j];
      const float tm = IntersectCapsule(MakeCapsuleOrigin(o, Float3{sp.a[0], sp.a[1], sp.a[2]},
                                                          Float3{sp.b[0], sp.b[1], sp.b[2]}, sp.r),
                                        du);
      if (tm > 0 && tm / len < best_t) best_t = tm / len, best = j;
    }
    ASSERT_EQ(hit, best >= 0) << "ray " << i;
    if (!hit) continue;
    ++hits;
    EXPECT_EQ(t, best_t) << "ray " << i;
    EXPECT_EQ(streaks.streaks[k].prim, streaks.streaks[best].prim) << "ray " << i;
  }
  std::printf(
      "%s 64x48 16 spp (%d streaks, BVH built in %.2f ms on the host, %d of %d camera rays meet "
      "one): radiance mean relative difference %.4f %% (8x8 blocks), %.4f %% (image mean); "
      "without the streaks %.2f %%\n",
      world.c_str(), streaks.num, data.path_streaks().build_ms(), hits, 64 * 48 * 4, 100 * tile,
      100 * mean, 100 * tile_clear);
  EXPECT_GT(hits, 0);
  EXPECT_LE(tile, kHostParticleTolerance);
  EXPECT_LE(mean, kHostParticleTolerance);
  EXPECT_GT(tile_clear, 4 * kHostParticleTolerance);
  EXPECT_EQ(0, std::memcmp(got.radiance.data(), again.radiance.data(),
                           sizeof(Float3) * got.radiance.size()));
}

INSTANTIATE_TEST_SUITE_P(Effects, PathtracedHostParticles,
                         ::testing::Values(std::make_pair(std::string("rain.yaml"), 0),
                                           std::make_pair(std::string("snow.yaml"), 0),
                                           std::make_pair(std::string("fire.yaml"), 1)));

// the realtime tier's media volumes are not built for the paths: Prepare gets the effects
// without their media (the path kernels trace the media themselves).
TEST(EffectsWithoutMedia, DropsTheMediaAndKeepsTheRest) {
  EffectsFrame fog;
  fog.homogeneous_media.emplace_back();
  EffectsFrame smoke;
  smoke.grid_media.emplace_back();
  EffectsFrame storage;
  EXPECT_EQ(cuda::EffectsWithoutMedia(&smoke, &storage), nullptr);
  EXPECT_EQ(cuda::EffectsWithoutMedia(&fog, &storage), nullptr);
  fog.surface_wetness = 0.5f;
  const EffectsFrame* lit = cuda::EffectsWithoutMedia(&fog, &storage);
  ASSERT_NE(lit, nullptr);
  EXPECT_TRUE(lit->homogeneous_media.empty());
  EXPECT_EQ(lit->surface_wetness, 0.5f);
  EffectsFrame rain;
  rain.particles.emplace_back();
  EXPECT_EQ(cuda::EffectsWithoutMedia(&rain, &storage), &rain);
}

}  // namespace
}  // namespace penumbra
