// the CUDA backend's realtime rgb path, run on the CPU (RenderRealtimeOnHost: the very
// PB_HOST_DEVICE per-pixel functions the kernels run, over the host BVH), against the CPU
// backend on the bundled default, house, warehouse and outdoor worlds and effects/walkers.yaml
// (its rover's mirror materials, reflectance 0.2 and 0.4: the mirror layer) at 160x120: rgb PSNR
// >= 40 dB (the `gpu` test RealtimeRgbGpu checks it at 640x480 on the GPU)
// and depth within 1 mm on >= 99.9 % of pixels; two renders are bit-identical. no GPU needed.

#include "penumbra/render/cuda/realtime_host.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "penumbra/core/error.h"
#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/render/camera/camera.h"
#include "penumbra/render/frame/bvh_scene.h"
#include "realtime_parity.h"
#include "render/render_test_util.h"

namespace penumbra {
namespace {

// the CPU backend's frame of `view` (want) and the GPU path's run on the host (got, and a second
// render: again).
struct HostPathFrames {
  RenderedFrame want, got, again;
};
HostPathFrames RenderCpuAndHostPath(const SceneDescription& scene, const WorldSnapshot& snap,
                                    const CameraView& view) {
  RenderSettings settings;
  settings.backend = RenderSettings::Backend::kEmbree;
  HostPathFrames f;
  MakeRenderer(scene, settings)->Render(snap, view, &f.want);
  cuda::BvhScene bvh(scene);
  bvh.Update(snap);
  cuda::RealtimeFrameData data(scene, settings);
  ThreadPool pool(0);
  data.Prepare(snap, view, &pool);
  cuda::RenderRealtimeOnHost(data, bvh, &pool, &f.got);
  cuda::RenderRealtimeOnHost(data, bvh, &pool, &f.again);
  return f;
}

class RealtimeHostPath : public ::testing::TestWithParam<std::string> {};

TEST_P(RealtimeHostPath, MatchesCpuBackend) {
  const auto [session, snap, view, fx] = realtime_parity::LoadFrameAt(GetParam(), 1.0, 160, 120);
  const SceneDescription& scene = session->scene();
  const auto [want, got, again] = RenderCpuAndHostPath(scene, snap, view);
  const double psnr = realtime_parity::Psnr(want.rgb, got.rgb);
  const double depth_bad = realtime_parity::DepthMismatch(want.depth_m, got.depth_m);
  std::printf(
      "%s 160x120: rgb PSNR %.2f dB, ev100 cpu %.4f host-gpu-path %.4f, depth > 1 mm on "
      "%.4f %% of pixels\n",
      GetParam().c_str(), psnr, want.ev100, got.ev100, 100 * depth_bad);
  // measured with the mirror layer on the GPU path
  // (docs/journal/2026-11-26-gpu-effects.md, "Where the realtime rgb
  // differs"): default 95.7 dB, house 81.4, warehouse 61.6, outdoor 66.8, walkers 92.7 (48.8
  // and 29.8 without it).
  EXPECT_GE(psnr, 40.0);
  EXPECT_LE(depth_bad, 0.001);
  EXPECT_EQ(got.rgb.data, again.rgb.data);
  EXPECT_EQ(got.radiance.data, again.radiance.data);
}

INSTANTIATE_TEST_SUITE_P(Bundled, RealtimeHostPath,
                         ::testing::Values("default.yaml", "house.yaml", "warehouse.yaml",
                                           "outdoor.yaml", "effects/walkers.yaml"));

// a camera with lens distortion (Brown-Conrady k1 k2 p1) and a moving camera with a rolling
// shutter: the GPU path's rays come from the camera's ray tables (camera_rays.h, the CPU's own
// Camera::Unproject and PoseAtRow), and the frame matches the CPU backend's as a pinhole's does
// (rgb PSNR >= 40 dB, depth within 1 mm on >= 99.9 % of pixels); without the tables (the plain
// pinhole rays) it does not.
TEST(RealtimeHostPathFrames, DistortedAndRollingShutterCamerasMatchTheCpuBackend) {
  const auto [session, snap, pinhole, fx] =
      realtime_parity::LoadFrameAt("default.yaml", 1.0, 160, 120);
  const SceneDescription& scene = session->scene();
  CameraView distorted = pinhole;
  distorted.intrinsics.k1 = -0.28;
  distorted.intrinsics.k2 = 0.07;
  distorted.intrinsics.p1 = 0.002;
  CameraView rolling = pinhole;
  rolling.motion.end_sec = 0.03;
  rolling.motion.line_time_sec = 0.03 / 120;
  rolling.motion.X_WO_end = pinhole.X_WO;
  rolling.motion.X_WO_end.translation() += Eigen::Vector3d(0.15, 0.05, 0);
  rolling.motion.X_WO_end.linear() =
      Eigen::AngleAxisd(0.25, Eigen::Vector3d::UnitZ()).toRotationMatrix() * pinhole.X_WO.linear();
  CameraView both = distorted;
  both.motion = rolling.motion;
  RenderSettings settings;
  settings.backend = RenderSettings::Backend::kEmbree;
  const std::unique_ptr<Renderer> cpu = MakeRenderer(scene, settings);
  cuda::BvhScene bvh(scene);
  bvh.Update(snap);
  ThreadPool pool(0);
  // the GPU path's frame with the plain pinhole's rays (no tables)
  cuda::RealtimeFrameData plain(scene, settings);
  plain.Prepare(snap, pinhole, &pool);
  RenderedFrame pinhole_frame;
  cuda::RenderRealtimeOnHost(plain, bvh, &pool, &pinhole_frame);
  for (const auto& [name, view] :
       {std::pair{"distorted", distorted}, std::pair{"rolling shutter", rolling},
        std::pair{"distorted + rolling shutter", both}}) {
    SCOPED_TRACE(name);
    RenderedFrame want;
    cpu->Render(snap, view, &want);
    cuda::RealtimeFrameData data(scene, settings);
    data.Prepare(snap, view, &pool);
    RenderedFrame got;
    cuda::RenderRealtimeOnHost(data, bvh, &pool, &got);
    const double psnr = realtime_parity::Psnr(want.rgb, got.rgb);
    const double depth_bad = realtime_parity::DepthMismatch(want.depth_m, got.depth_m);
    const double pinhole_psnr = realtime_parity::Psnr(want.rgb, pinhole_frame.rgb);
    std::printf("%s 160x120: rgb PSNR %.2f dB (pinhole rays: %.2f), depth > 1 mm on %.4f %%\n",
                name, psnr, pinhole_psnr, 100 * depth_bad);
    EXPECT_GE(psnr, 40.0);
    EXPECT_LE(depth_bad, 0.001);
    EXPECT_LT(pinhole_psnr, 30.0);
  }
}

// a visible spatial tendon (a capsule around each segment of its path, render/cuda/bvh_scene.h)
// lit by a lamp over a floor: the GPU path draws it as the CPU backend does (rgb PSNR >= 40 dB,
// depth within 1 mm), segmentation -1 on it.
TEST(RealtimeHostPathFrames, TendonsAreDrawnAsTheCpuBackendDrawsThem) {
  SceneDescription scene = testing::EmptyScene();
  testing::AddGeom(&scene, GeomShape::kPlane, {0, 0, 1}, Pose::Identity(), 0,
                   testing::AddMaterial(&scene, {0.6f, 0.6f, 0.6f}));
  testing::AddPointLamp(&scene, {1.5, 0.5, 2.0}, 40, 0.05f);
  Tendon rope;
  rope.name = "rope";
  rope.width_m = 0.05;
  rope.material = testing::AddMaterial(&scene, {0.8f, 0.1f, 0.1f}, 0.5f);
  scene.tendons.push_back(rope);
  WorldSnapshot snap = testing::IdentitySnapshot(scene);
  snap.tendon_paths = {{0, {{3, -0.3, 0.05}, {3, -0.3, 0.6}, {3, 0.3, 0.9}}}};
  CameraView view = testing::MakeView(testing::CameraLookingAlongX({0, 0, 0.6}), 160, 120, 60);
  view.outputs[ImageKind::kSegmentation] = true;
  const auto [want, got, again] = RenderCpuAndHostPath(scene, snap, view);
  int tendon_pixels = 0;
  for (size_t i = 0; i < want.geom_id.data.size(); ++i)
    tendon_pixels += want.geom_id.data[i] == -1 && want.depth_m.data[i] > 0;
  const double psnr = realtime_parity::Psnr(want.rgb, got.rgb);
  std::printf("tendon 160x120: %d tendon pixels, rgb PSNR %.2f dB\n", tendon_pixels, psnr);
  EXPECT_GT(tendon_pixels, 100);
  EXPECT_GE(psnr, 40.0);
  EXPECT_LE(realtime_parity::DepthMismatch(want.depth_m, got.depth_m), 0.001);
}

// the kernels shade from the material terms the geometry pass kept (ShadeRealtimeStored)
// instead of evaluating the surface again: the same
// radiance, rgb and depth bits, in the default room (planar textures, mirror floor) and the
// house (textured floors and walls, normal maps); so do the lights' terms kept in an array
// interleaved over a row's pixels (StridedLightTerms, as the shading kernel's shared memory)
// and the shadow rays apart in three passes (the kernels' queued shadow rays:
// ShadeQueuedStored, the rays traced from the queue's entries, SumQueuedLights), whose sum keeps
// light order: summed from the last light to the first, the radiance and EV100 differ in both;
// and so does the shared visibility worked by 16x16 shadow tiles, each tile's arrays copied as
// the kernels copy them into shared memory (120 rows: the last row of tiles is cut at 8).
TEST(RealtimeHostPathFrames, StoredSurfaceShadesTheSameBits) {
  for (const char* world : {"default.yaml", "house.yaml"}) {
    const auto [session, snap, view, fx] = realtime_parity::LoadFrameAt(world, 1.0, 160, 120);
    const SceneDescription& scene = session->scene();
    cuda::BvhScene bvh(scene);
    bvh.Update(snap);
    cuda::RealtimeFrameData data(scene, RenderSettings());
    ThreadPool pool(0);
    data.Prepare(snap, view, &pool);
    RenderedFrame evaluated, stored, strided, queued, tiled;
    cuda::RenderRealtimeOnHost(data, bvh, &pool, &evaluated, /*stored_surface=*/false);
    cuda::RenderRealtimeOnHost(data, bvh, &pool, &stored, /*stored_surface=*/true);
    cuda::RenderRealtimeOnHost(data, bvh, &pool, &strided, /*stored_surface=*/true,
                               /*strided_terms=*/true);
    cuda::RenderRealtimeOnHost(data, bvh, &pool, &queued, /*stored_surface=*/true,
                               /*strided_terms=*/false, /*queued_shadows=*/true);
    cuda::RenderRealtimeOnHost(data, bvh, &pool, &tiled, /*stored_surface=*/true,
                               /*strided_terms=*/false, /*queued_shadows=*/false,
                               /*tiled_visibility=*/true);
    int64_t lit = 0;
    for (float x : stored.radiance.data) lit += x > 0;
    EXPECT_GT(lit, 0) << world;
    EXPECT_EQ(stored.radiance.data, evaluated.radiance.data) << world;
    EXPECT_EQ(stored.rgb.data, evaluated.rgb.data) << world;
    EXPECT_EQ(stored.depth_m.data, evaluated.depth_m.data) << world;
    // the lights' terms interleaved over the row's pixels (the kernels' shared memory)
    EXPECT_EQ(strided.radiance.data, stored.radiance.data) << world;
    EXPECT_EQ(strided.rgb.data, stored.rgb.data) << world;
    // the shadow rays through the queue
    EXPECT_EQ(queued.radiance.data, stored.radiance.data) << world;
    EXPECT_EQ(queued.rgb.data, stored.rgb.data) << world;
    EXPECT_EQ(queued.depth_m.data, stored.depth_m.data) << world;
    EXPECT_EQ(queued.ev100, stored.ev100) << world;
    // the shared visibility by shadow tiles (the kernels' shared memory)
    EXPECT_EQ(tiled.radiance.data, stored.radiance.data) << world;
    EXPECT_EQ(tiled.rgb.data, stored.rgb.data) << world;
  }
}

// batch rendering poses a world once (PoseWorld) and sets each camera of a batch in turn
// (SetCamera, FrameKey): a camera set after another one renders the bits of Prepare of that
// camera alone, in the default room and the house.
TEST(RealtimeHostPathFrames, PoseWorldThenSetCameraIsPrepare) {
  for (const char* world : {"default.yaml", "house.yaml"}) {
    auto [session, snap, view, fx] = realtime_parity::LoadFrameAt(world, 1.0, 64, 48);
    const SceneDescription& scene = session->scene();
    view.frame_index = 5;
    view.white_balance_gains = Eigen::Vector3f(0.9f, 1.0f, 1.2f);
    CameraView other = view;
    other.white_balance_gains = Eigen::Vector3f::Ones();
    other.X_WO.translation().z() += 0.3;
    other.frame_index = 2;
    cuda::BvhScene bvh(scene);
    bvh.Update(snap);
    ThreadPool pool(0);
    cuda::RealtimeFrameData alone(scene, RenderSettings());
    alone.Prepare(snap, view, &pool);
    cuda::RealtimeFrameData batch(scene, RenderSettings());
    batch.PoseWorld(snap, &pool);
    for (const CameraView* v : {&other, &view}) {
      const Camera c(v->X_WO, v->intrinsics, v->motion);
      batch.SetCamera(cuda::PinholeCameraOf(*v), c.pixel_spread_rad(), v->camera_index,
                      v->frame_index, v->white_balance_gains);
    }
    const cuda::RealtimeFrameView fa = alone.View(bvh.view(), nullptr);
    const cuda::RealtimeFrameView fb = batch.View(bvh.view(), nullptr);
    EXPECT_EQ(fa.frame_key, fb.frame_key) << world;
    EXPECT_EQ(fb.frame_key, batch.FrameKey(view.camera_index, view.frame_index)) << world;
    EXPECT_NE(fb.frame_key, batch.FrameKey(other.camera_index, other.frame_index)) << world;
    EXPECT_EQ(fa.spread_rad, fb.spread_rad) << world;
    EXPECT_EQ(0, std::memcmp(&fa.camera, &fb.camera, sizeof(fa.camera))) << world;
    RenderedFrame a, b;
    cuda::RenderRealtimeOnHost(alone, bvh, &pool, &a, /*stored_surface=*/true);
    cuda::RenderRealtimeOnHost(batch, bvh, &pool, &b, /*stored_surface=*/true);
    EXPECT_EQ(a.rgb.data, b.rgb.data) << world;
    EXPECT_EQ(a.depth_m.data, b.depth_m.data) << world;
    EXPECT_EQ(a.ev100, b.ev100) << world;
  }
}

// PoseWorld poses again only the geoms of bodies that moved since its last call: frames
// prepared one after the other hold the geoms, lights and rendered bits of data prepared for
// the last snapshot alone; a body moved by hand (every geom of the world's last moving body)
// is followed too.
TEST(RealtimeHostPathFrames, PoseWorldFollowsMovedBodiesOnly) {
  for (const char* world : {"default.yaml", "house.yaml"}) {
    const std::unique_ptr<Session> session = realtime_parity::LoadSimulated(world);
    const SceneDescription& scene = session->scene();
    const WorldSnapshot first = session->sim().Snapshot();
    while (session->sim().time() < 1.5) session->sim().Step();
    WorldSnapshot later = session->sim().Snapshot();
    // one more body moved by hand: the last geom's body (not the world's)
    const int b = scene.geoms.back().body;
    if (b > 0) later.X_WB[b].translation().x() += 0.05;
    const CameraView view = realtime_parity::RgbDepthView(scene, later, 64, 48);
    ThreadPool pool(0);
    cuda::RealtimeFrameData reused(scene, RenderSettings());
    reused.Prepare(first, view, &pool);
    reused.Prepare(first, view, &pool);
    reused.Prepare(later, view, &pool);
    cuda::RealtimeFrameData fresh(scene, RenderSettings());
    fresh.Prepare(later, view, &pool);
    ASSERT_EQ(reused.geoms().size(), fresh.geoms().size());
    EXPECT_EQ(0, std::memcmp(reused.geoms().data(), fresh.geoms().data(),
                             sizeof(fresh.geoms()[0]) * fresh.geoms().size()))
        << world;
    ASSERT_EQ(reused.lights().size(), fresh.lights().size());
    EXPECT_EQ(0, std::memcmp(reused.lights().data(), fresh.lights().data(),
                             sizeof(fresh.lights()[0]) * fresh.lights().size()))
        << world;
    cuda::BvhScene bvh(scene);
    bvh.Update(later);
    RenderedFrame a, c;
    cuda::RenderRealtimeOnHost(reused, bvh, &pool, &a, /*stored_surface=*/true);
    cuda::RenderRealtimeOnHost(fresh, bvh, &pool, &c, /*stored_surface=*/true);
    EXPECT_EQ(a.rgb.data, c.rgb.data) << world;
    EXPECT_EQ(a.radiance.data, c.radiance.data) << world;
  }
}

// the GPU's Render() asks for the sky terms band by band (rows [r0, r1)): every pixel's bits are
// those of the whole frame's pass, primary and mirrored; odd bounds before the last row are
// refused (a 2x2 quad would be split).
TEST(RealtimeHostPathFrames, SkyTermsInBandsEqualTheWholeFrame) {
  // the default room: a sky volume (its walls) and a mirror layer (the floor's reflectance)
  const auto [session, snap, view, fx] =
      realtime_parity::LoadFrameAt("default.yaml", 1.0, 160, 119);
  const SceneDescription& scene = session->scene();
  cuda::BvhScene bvh(scene);
  bvh.Update(snap);
  cuda::RealtimeFrameData data(scene, RenderSettings());
  ThreadPool pool(0);
  data.Prepare(snap, view, &pool);
  ASSERT_TRUE(data.any_mirror());
  const int W = data.camera().width, H = data.camera().height;
  ASSERT_EQ(H, 119);
  const int64_t n = static_cast<int64_t>(W) * H;
  const cuda::RealtimeFrameView geo_view = data.View(bvh.view(), nullptr);
  std::vector<cuda::PixelGeometry> geometry(n), mirror(n);
  std::vector<cuda::TraceHit> mirror_hits(n);
  std::vector<float> depth(n);
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u)
      geometry[static_cast<int64_t>(v) * W + u] =
          cuda::PrimaryGeometry(geo_view, u, v, &depth[static_cast<int64_t>(v) * W + u]);
  cuda::RealtimeFrameView mirror_view = geo_view;
  mirror_view.geometry = geometry.data();
  mirror_view.mirror_geometry = mirror.data();
  mirror_view.mirror_hits = mirror_hits.data();
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) cuda::TraceMirrorRay(mirror_view, u, v);
  const Float3 unset{-1, -1, -1};
  std::vector<Float3> whole(n, unset), banded(n, unset), mirror_whole(n, unset),
      mirror_banded(n, unset);
  data.SkyTerms(geometry.data(), n, whole.data(), &pool);
  data.MirrorSkyTerms(mirror.data(), n, mirror_whole.data(), &pool);
  const int bounds[] = {0, 30, 60, 90, H};
  for (int k = 0; k + 1 < 5; ++k) {
    data.SkyTerms(geometry.data(), n, banded.data(), &pool, bounds[k], bounds[k + 1]);
    data.MirrorSkyTerms(mirror.data(), n, mirror_banded.data(), &pool, bounds[k], bounds[k + 1]);
  }
  int64_t differ = 0, mirrored = 0;
  for (int64_t i = 0; i < n; ++i) {
    differ += std::memcmp(&whole[i], &banded[i], sizeof(Float3)) != 0;
    differ += std::memcmp(&mirror_whole[i], &mirror_banded[i], sizeof(Float3)) != 0;
    mirrored += mirror[i].hit >= 0;
  }
  EXPECT_EQ(differ, 0);
  EXPECT_GT(mirrored, 0);
  EXPECT_THROW(data.SkyTerms(geometry.data(), n, banded.data(), &pool, 1, 30), Error);
  EXPECT_THROW(data.SkyTerms(geometry.data(), n, banded.data(), &pool, 0, 31), Error);
}

// the window's sums in integers (SharedWindowFraction over ShadowWindowCounts, packed at each
// tap or once into a tile's copy) against the float sums written out here (the plain
// form: the window's bits in order, w ShadowWindowWeight, neighbours without a verdict
// left out): the same bits for 200,000 random windows and counts (traced 1 to 64, visible 0 to
// traced, a quarter of the neighbours without a verdict), and for the tile ring's own fraction.
TEST(RealtimeHostPathFrames, WindowSumsInIntegersGiveTheFloatSumsBits) {
  constexpr int kSide = kShadowTileSize, kAt = 8 * kSide + 8;
  std::mt19937 rng(35);
  std::uniform_int_distribution<int> ray_count(1, 64), quarter(0, 3);
  std::vector<int8_t> vis(kSide * kSide);
  std::vector<float> visible(kSide * kSide), rays(kSide * kSide);
  std::vector<uint32_t> counts(kSide * kSide);
  int64_t differ = 0, differ_packed = 0, differ_own = 0, fractions_seen = 0;
  float last = -1;
  for (int trial = 0; trial < 200000; ++trial) {
    for (int k = 0; k < kSide * kSide; ++k) {
      const int r = trial % 7 == 0 ? 64 : ray_count(rng);
      vis[k] = k != kAt && quarter(rng) == 0 ? int8_t{-1} : static_cast<int8_t>(quarter(rng) & 1);
      rays[k] = static_cast<float>(r);
      visible[k] = static_cast<float>(std::uniform_int_distribution<int>(0, r)(rng));
      counts[k] = ShadowWindowCounts(vis[k], visible[k], rays[k]);
    }
    const uint32_t window = (static_cast<uint32_t>(rng()) & ((1u << kShadowWindowTaps) - 1u)) |
                            1u << ShadowWindowBit(0, 0);
    float w_rays = 0, w_visible = 0;
    for (uint32_t b = window; b != 0; b &= b - 1) {
      const int bit = LowestSetBit(b);
      const int dy = bit / 5 - 2, dx = bit % 5 - 2;
      const int kk = kAt + dy * kSide + dx;
      if (vis[kk] < 0) continue;
      w_rays += ShadowWindowWeight(dx, dy) * rays[kk];
      w_visible += ShadowWindowWeight(dx, dy) * visible[kk];
    }
    const float want = w_visible / w_rays;
    cuda::VisibilityTaps taps{vis.data(), visible.data(), rays.data(), nullptr, kSide};
    const float got = cuda::SharedWindowFraction(taps, kAt, window, false);
    const float own = cuda::SharedWindowFraction(taps, kAt, window, true);
    taps.counts = counts.data();
    const float got_packed = cuda::SharedWindowFraction(taps, kAt, window, false);
    differ += std::memcmp(&got, &want, sizeof(float)) != 0;
    differ_packed += std::memcmp(&got_packed, &want, sizeof(float)) != 0;
    const float own_want = visible[kAt] / rays[kAt];
    differ_own += std::memcmp(&own, &own_want, sizeof(float)) != 0;
    fractions_seen += want != last;
    last = want;
  }
  EXPECT_EQ(differ, 0);
  EXPECT_EQ(differ_packed, 0);
  EXPECT_EQ(differ_own, 0);
  EXPECT_GT(fractions_seen, 100000);  // the fractions vary: not a comparison of constants
}

// the staged window (the visibility kernel's shared-memory copy of a tile) against the unstaged
// forms written out here: on random 16x16 tiles (cut to 9 .. 16 columns and rows, as the
// image's edges cut them) of surfaces and of one light's verdicts (-1, 0, 1; a third of the
// tiles all visible but for misses), every pixel's window mask over the tile's copied surfaces
// (TileWindowSurfaces) is the mask read from the PixelGeometry records (the old loop:
// SameShadowSurface on each in-tile neighbour with a hit), and its own verdict and "both
// verdicts seen" from the tile's bit rows (RowWindowVerdicts: ShadowVerdictBits,
// ShadowWindowVerdicts) are the old loop's over the int8 verdicts (each set bit in turn),
// for random windows and for the pixels' own masks. the rows read with one window row's shift
// off by one column give other booleans (the comparison can fail).
TEST(RealtimeHostPathFrames, StagedWindowGivesTheSameMasksAndVerdicts) {
  constexpr int kSide = kShadowTileSize, kPixels = kSide * kSide;
  std::mt19937 rng(32);
  std::uniform_int_distribution<int> side(9, kSide), quarter(0, 3), geom(-1, 1), normal(0, 2);
  std::uniform_real_distribution<float> jitter(-0.05f, 0.05f);
  std::vector<cuda::PixelGeometry> geometry(kPixels);
  std::vector<int8_t> vis(kPixels);
  int32_t key[kPixels];
  float ng[3][kPixels], pt[3][kPixels];
  uint32_t rows[kShadowVerdictRows];
  int64_t mask_differ = 0, own_differ = 0, seen_differ = 0, wrong_differ = 0, both = 0,
          one_only = 0, partial_masks = 0, checked = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    const ShadowTile tile{0, 0, side(rng), side(rng)};
    const bool all_visible = trial % 3 == 0;
    for (int k = 0; k < kPixels; ++k) {
      cuda::PixelGeometry& g = geometry[k];
      const int x = k % kSide, y = k / kSide;
      const bool in = x < tile.width && y < tile.height;
      g.hit = in && quarter(rng) != 0 ? 1 : 0;
      g.geom = geom(rng);
      const int a = normal(rng);
      g.ng = Float3{a == 0 ? 1.0f : jitter(rng), a == 1 ? 1.0f : jitter(rng) * 8,
                    a == 2 ? 1.0f : jitter(rng)};
      g.p_or_d = Float3{0.01f * x + jitter(rng) * 0.02f, 0.01f * y, jitter(rng) * 0.01f};
      const int q = quarter(rng);
      vis[k] = !in || q == 0 ? int8_t{-1} : all_visible ? int8_t{1} : static_cast<int8_t>(q & 1);
      key[k] = cuda::TileWindowSurfaces::KeyOf(g);
      ng[0][k] = g.ng.x, ng[1][k] = g.ng.y, ng[2][k] = g.ng.z;
      pt[0][k] = g.p_or_d.x, pt[1][k] = g.p_or_d.y, pt[2][k] = g.p_or_d.z;
    }
    std::fill(std::begin(rows), std::end(rows), 0u);
    for (int k = 0; k < kPixels; ++k)
      rows[kShadowWindowRadius + k / kSide] |= ShadowVerdictBits(k % kSide, vis[k]);
    const cuda::TileWindowSurfaces staged{key, ng[0], ng[1], ng[2], pt[0], pt[1], pt[2]};
    for (int y = 0; y < tile.height; ++y)
      for (int x = 0; x < tile.width; ++x) {
        const int at = y * kSide + x;
        // main's window mask: every in-tile neighbour with a hit on the same surface
        uint32_t want_mask = 0;
        const cuda::PixelGeometry& gi = geometry[at];
        if (gi.hit != 0) {
          const float ng_i[3] = {gi.ng.x, gi.ng.y, gi.ng.z},
                      p_i[3] = {gi.p_or_d.x, gi.p_or_d.y, gi.p_or_d.z};
          for (int dy = -2; dy <= 2; ++dy)
            for (int dx = -2; dx <= 2; ++dx) {
              if (y + dy < 0 || y + dy >= tile.height || x + dx < 0 || x + dx >= tile.width)
                continue;
              const cuda::PixelGeometry& g = geometry[at + dy * kSide + dx];
              const float ng_g[3] = {g.ng.x, g.ng.y, g.ng.z},
                          p_g[3] = {g.p_or_d.x, g.p_or_d.y, g.p_or_d.z};
              if ((dx != 0 || dy != 0) &&
                  (g.hit == 0 || !SameShadowSurface(gi.geom, ng_i, p_i, g.geom, ng_g, p_g)))
                continue;
              want_mask |= 1u << ShadowWindowBit(dx, dy);
            }
        }
        const uint32_t mask = cuda::ShadowWindowMask(staged, at, kSide, x, y, tile);
        const uint32_t frame_mask = cuda::ShadowWindowMask(
            cuda::FrameWindowSurfaces{geometry.data()}, at, kSide, x, y, tile);
        mask_differ += (mask != want_mask) + (frame_mask != want_mask);
        partial_masks += want_mask != 0 && want_mask != (1u << ShadowWindowBit(0, 0)) &&
                         __builtin_popcount(want_mask) < 9;
        // a random window cut to the tile, and the pixel's own mask
        uint32_t cut = 0;
        for (int dy = -2; dy <= 2; ++dy)
          for (int dx = -2; dx <= 2; ++dx)
            if (y + dy >= 0 && y + dy < tile.height && x + dx >= 0 && x + dx < tile.width)
              cut |= 1u << ShadowWindowBit(dx, dy);
        for (const uint32_t bits : {static_cast<uint32_t>(rng()) & cut, want_mask}) {
          // main's test: each set bit's verdict in turn
          bool want[2] = {false, false};
          for (int bit = 0; bit < kShadowWindowTaps; ++bit) {
            if ((bits >> bit & 1u) == 0) continue;
            const int8_t w = vis[at + (bit / 5 - 2) * kSide + (bit % 5 - 2)];
            if (w >= 0) want[w] = true;
          }
          const cuda::RowWindowVerdicts r{rows, x, y};
          bool seen[2];
          r.Seen(bits, seen);
          own_differ += r.Own() != vis[at];
          seen_differ += seen[0] != want[0] || seen[1] != want[1];
          both += want[0] && want[1];
          one_only += want[0] != want[1];
          ++checked;
          // window row 1 (dy = -1) shifted one column too far
          uint32_t ones = 0, zeros = 0;
          for (int wr = 0; wr < 5; ++wr) {
            const uint32_t w = bits >> (5 * wr) & 31u, row = rows[y + wr];
            const int shift = wr == 1 ? x + 1 : x;
            ones |= ((row & 0xffffu) << 2 >> shift) & w;
            zeros |= ((row >> 16) << 2 >> shift) & w;
          }
          wrong_differ += (zeros != 0) != want[0] || (ones != 0) != want[1];
        }
      }
  }
  EXPECT_EQ(mask_differ, 0);
  EXPECT_EQ(own_differ, 0);
  EXPECT_EQ(seen_differ, 0);
  // not a comparison of constants: windows see both verdicts or one, masks are cut by surfaces
  EXPECT_GT(both, checked / 10);
  EXPECT_GT(one_only, checked / 10);
  EXPECT_GT(partial_masks, checked / 20);
  EXPECT_GT(wrong_differ, checked / 100);
  std::printf(
      "staged window: %lld windows, %lld see both verdicts, %lld one; shift off by one: "
      "%lld differ\n",
      static_cast<long long>(checked), static_cast<long long>(both),
      static_cast<long long>(one_only), static_cast<long long>(wrong_differ));
}

}  // namespace
}  // namespace penumbra
