// per-frame state of the realtime effects structures: RealtimeMedia and ParticleScene keep
// tables and buffers between Build calls (for their capacity) and per-frame shortcuts (the
// camera's relative fog density, pixel / quad column tables); a rebuilt object must answer
// exactly as a freshly built one, and the shortcuts must give the values of the full formulas.

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

#include "penumbra/core/thread_pool.h"
#include "penumbra/render/camera/camera.h"
#include "penumbra/render/embree/particle_scene.h"
#include "penumbra/render/embree/ray_scene.h"
#include "penumbra/render/light/light_sampler.h"
#include "penumbra/render/media/media_realtime.h"
#include "penumbra/render/media/media_scene.h"
#include "render/media_test_util.h"

namespace penumbra::testing {
namespace {

bool SameBits(const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
  return std::memcmp(a.data(), b.data(), sizeof(float) * 3) == 0;
}

bool SameBits(const MediaSegment& a, const MediaSegment& b) {
  return SameBits(a.T, b.T) && SameBits(a.L_add, b.L_add);
}

// a point light, height fog (coloured or grey) and optionally a smoke ramp; media of `fx`.
struct MediaSetup {
  SceneDescription scene;
  EffectsFrame fx;
  MediaSetup(bool grey, bool smoke) {
    scene = EmptyScene();
    Light l;
    l.type = Light::Type::kPoint;
    l.position_B = {4, 1.5, 2.5};
    l.intensity = 200;
    scene.lights.push_back(l);
    HomogeneousMedium fog = Fog(0.25f, 0.9f, 0.3f);
    if (!grey) fog.sigma_t_per_m = Eigen::Vector3f(0.2f, 0.25f, 0.3f);
    fog.height_falloff_per_m = 0.1f;
    fog.base_height_m = 0.5f;
    fx.homogeneous_media.push_back(fog);
    if (smoke)
      fx.grid_media.push_back(RampGrid({5, 0, 1}, {3, 3, 1.5}, 24, 1.0f, 0.25f, 1.5f, 0.8f));
  }
};

TEST(EffectsRebuildTest, RebuiltRealtimeMediaMatchesFreshOne) {
  // frame 1: coloured fog, no smoke, a 96 x 64 camera low down; frame 2: grey fog and smoke,
  // a 160 x 120 camera higher up. the object rebuilt for frame 2 answers as a fresh one.
  MediaSetup a(false, false), b(true, true);
  const WorldSnapshot snap = IdentitySnapshot(b.scene);
  LightSampler lights(b.scene);
  lights.Update(snap);
  RayScene rays(b.scene);
  rays.Update(snap);
  const CameraView view_a = MakeView(CameraLookingAlongX({0, 0, 0.3}), 96, 64, 60.0);
  const CameraView view_b = MakeView(CameraLookingAlongX({0, 0.2, 1.2}), 160, 120, 70.0);
  const Camera cam_a(view_a.X_WO, view_a.intrinsics), cam_b(view_b.X_WO, view_b.intrinsics);
  MediaScene media_a, media_b;
  media_a.Build(&a.fx);
  media_b.Build(&b.fx);
  ThreadPool pool(2);
  RealtimeMedia reused, fresh;
  reused.Build(media_a, lights, rays, cam_a, 11, Eigen::Vector3f(5, 0, 1), 8.0,
               Eigen::Vector3f::Constant(0.3f), nullptr, &pool);
  reused.Build(media_b, lights, rays, cam_b, 22, Eigen::Vector3f(5, 0, 1), 8.0,
               Eigen::Vector3f::Constant(0.4f), nullptr, &pool);
  fresh.Build(media_b, lights, rays, cam_b, 22, Eigen::Vector3f(5, 0, 1), 8.0,
              Eigen::Vector3f::Constant(0.4f), nullptr, nullptr);
  int compared = 0, with_light = 0;
  for (int v = 0; v < 120; v += 3) {
    for (int u = 0; u < 160; u += 3) {
      const Ray r = cam_b.GenerateRay(static_cast<float>(u), static_cast<float>(v));
      const Eigen::Vector3f d = r.d.normalized();
      for (float t : {0.1f, 2.0f, 6.5f, 40.0f, std::numeric_limits<float>::infinity()}) {
        const MediaSegment x = reused.IntegrateView(lights, r.o, d, t, u, v);
        const MediaSegment y = fresh.IntegrateView(lights, r.o, d, t, u, v);
        EXPECT_TRUE(SameBits(x, y)) << u << " " << v << " " << t;
        with_light += x.L_add.maxCoeff() > 0 ? 1 : 0;
        if (u + 1 < 160 && v + 1 < 120) {
          MediaQuad qx, qy;
          reused.PrepareQuad(u, v, t, r.o, d, &qx);
          fresh.PrepareQuad(u, v, t, r.o, d, &qy);
          EXPECT_TRUE(SameBits(reused.IntegrateView(lights, r.o, d, t, u, v, &qx),
                               fresh.IntegrateView(lights, r.o, d, t, u, v, &qy)))
              << u << " " << v << " " << t;
        }
        ++compared;
      }
      float Tx[kMaxVolumeLights] = {}, Ty[kMaxVolumeLights] = {};
      const Eigen::Vector3f p = r.o + 3.0f * d;
      ASSERT_EQ(reused.LightTransmittances(p, Tx), fresh.LightTransmittances(p, Ty));
      EXPECT_EQ(std::memcmp(Tx, Ty, sizeof(Tx)), 0);
    }
  }
  EXPECT_GT(compared, 9000);
  EXPECT_GT(with_light, compared / 2);  // the scenes do scatter light
}

TEST(EffectsRebuildTest, CameraDensityShortcutGivesTheFullFormula) {
  // fog only, no lights (no froxel volumes): IntegrateView is then the closed form alone. one
  // object is built for a camera at the rays' height (rays from there use the stored relative
  // density at the camera), the other for a camera 1 m higher (they compute it). the rays start
  // below, at and above the fog's base height (0.5 m) and look up, down and level.
  for (bool grey : {true, false}) {
    MediaSetup setup(grey, false);
    setup.scene.lights.clear();
    const WorldSnapshot snap = IdentitySnapshot(setup.scene);
    LightSampler lights(setup.scene);
    lights.Update(snap);
    RayScene rays(setup.scene);
    rays.Update(snap);
    MediaScene media;
    media.Build(&setup.fx);
    for (double z : {0.2, 0.5, 1.7}) {
      const CameraView at = MakeView(CameraLookingAlongX({0, 0, z}), 64, 48, 60.0);
      const CameraView above = MakeView(CameraLookingAlongX({0, 0, z + 1.0}), 64, 48, 60.0);
      const Camera cam_at(at.X_WO, at.intrinsics), cam_above(above.X_WO, above.intrinsics);
      RealtimeMedia x, y;
      x.Build(media, lights, rays, cam_at, 5, Eigen::Vector3f(5, 0, 1), 8.0,
              Eigen::Vector3f::Constant(0.4f), nullptr, nullptr);
      y.Build(media, lights, rays, cam_above, 5, Eigen::Vector3f(5, 0, 1), 8.0,
              Eigen::Vector3f::Constant(0.4f), nullptr, nullptr);
      const Eigen::Vector3f o = cam_at.GenerateRay(0, 0).o;
      for (float dz : {-0.5f, -1e-3f, 0.0f, 1e-3f, 0.5f}) {
        const Eigen::Vector3f d = Eigen::Vector3f(1.0f, 0.3f, dz).normalized();
        for (float t : {0.5f, 3.0f, 30.0f, std::numeric_limits<float>::infinity()}) {
          const MediaSegment sx = x.IntegrateView(lights, o, d, t, 10, 10);
          const MediaSegment sy = y.IntegrateView(lights, o, d, t, 10, 10);
          EXPECT_TRUE(SameBits(sx, sy)) << grey << " " << z << " " << dz << " " << t;
          EXPECT_LT(sx.T.maxCoeff(), 1.0f);  // the fog attenuates
        }
      }
    }
  }
}

// rain drops on a jittered lattice in front of a camera looking along x.
EffectsFrame Rain(int n, float x0, uint32_t seed) {
  EffectsFrame fx;
  ParticleSet rain;
  rain.kind = ParticleKind::kRain;
  uint32_t h = seed;
  auto next = [&h]() {
    h = h * 1664525u + 1013904223u;
    return static_cast<float>(h >> 8) / 16777216.0f;
  };
  for (int i = 0; i < n; ++i) {
    rain.position_W.emplace_back(x0 + 8.0f * next(), -3.0f + 6.0f * next(), -2.0f + 4.0f * next());
    rain.velocity_W.emplace_back(0.0f, 0.3f, -6.0f - next());
    rain.radius_m.push_back(0.0005f + 0.002f * next());
  }
  fx.particles.push_back(rain);
  HomogeneousMedium fog = Fog(0.2f, 0.9f);
  fx.homogeneous_media.push_back(fog);
  return fx;
}

TEST(EffectsRebuildTest, RebuiltParticleSceneMatchesFreshOne) {
  // a large frame, then a smaller one (the chunk buffers and pixel arrays shrink in use but
  // keep their old contents beyond it), then an empty one.
  const int W = 96, H = 72;
  const CameraView view = MakeView(CameraLookingAlongX({0, 0, 0}), W, H, 60.0);
  const Camera camera(view.X_WO, view.intrinsics);
  const EffectsFrame big = Rain(30000, 0.5f, 1), small = Rain(5000, 1.0f, 2);
  EffectsFrame none;
  none.particles.push_back(ParticleSet());
  MediaScene media_big, media_small;
  media_big.Build(&big);
  media_small.Build(&small);
  ThreadPool pool(2);
  ParticleScene reused;
  reused.Build(&big, camera, 0.01, StreakRays::kPixelCentres, &pool, &media_big);
  const int big_size = reused.size();
  EXPECT_GT(big_size, 200);
  EXPECT_GT(reused.culled(), 0);
  reused.Build(&small, camera, 0.01, StreakRays::kPixelCentres, &pool, &media_small);
  for (ThreadPool* p : {static_cast<ThreadPool*>(nullptr), &pool}) {
    ParticleScene fresh;
    fresh.Build(&small, camera, 0.01, StreakRays::kPixelCentres, p, &media_small);
    EXPECT_EQ(reused.size(), fresh.size());
    EXPECT_EQ(reused.culled(), fresh.culled());
    EXPECT_LE(reused.size() + reused.culled(), 5000);  // drops outside the view are skipped
    int hits = 0;
    for (int v = 0; v < H; ++v) {
      for (int u = 0; u < W; ++u) {
        const Ray r = camera.GenerateRay(static_cast<float>(u), static_cast<float>(v));
        ParticleHit a, b;
        const bool ha = reused.PixelHit(r, u, v, 1e30f, &a);
        const bool hb = fresh.PixelHit(r, u, v, 1e30f, &b);
        ASSERT_EQ(ha, hb) << u << " " << v;
        if (!ha) continue;
        ++hits;
        EXPECT_EQ(a.prim, b.prim);
        EXPECT_EQ(a.t, b.t);
        EXPECT_EQ(a.alpha, b.alpha);
        EXPECT_TRUE(SameBits(a.ng_W, b.ng_W));
      }
    }
    EXPECT_GT(hits, 100);
  }
  reused.Build(&none, camera, 0.01, StreakRays::kPixelCentres, &pool, nullptr);
  EXPECT_TRUE(reused.empty());
  ParticleHit h;
  EXPECT_FALSE(reused.PixelHit(camera.GenerateRay(40, 30), 40, 30, 1e30f, &h));
}

// drops all around the camera (a 4 m box): the scene of all of them and the scene of the
// subsequence near the view (centre within 20 degrees (moving: 50) of the image at X_WO, plus
// everything within 0.3 m (moving: 0.8 m) of the camera) keep the same streaks (the others are
// skipped, not culled) and give the same hit in every pixel.
void ExpectSkippedDropsChangeNoHit(bool moving) {
  const int W = 80, H = 60;
  const CameraView view = MakeView(CameraLookingAlongX({0.3, -0.2, 1.0}), W, H, 50.0);
  CameraMotion motion;
  if (moving) {
    // 6 degrees of yaw and 0.15 m during the exposure, a rolling shutter reading row 59 at
    // 1.2 x the exposure (the last rows extrapolate the motion).
    motion.X_WO_end = view.X_WO;
    motion.X_WO_end.linear() =
        Eigen::AngleAxisd(6 * M_PI / 180, Eigen::Vector3d::UnitZ()) * view.X_WO.linear();
    motion.X_WO_end.translation() += Eigen::Vector3d(0.1, 0.1, 0.05);
    motion.end_sec = 0.01;
    motion.time_sec = 0.002;
    motion.line_time_sec = 0.01 / 60;
  }
  const Camera camera(view.X_WO, view.intrinsics, motion);
  const double margin = (moving ? 50 : 20) * M_PI / 180;
  const float close_m = moving ? 0.8f : 0.3f;
  const EffectsFrame all = Rain(40000, -4.0f, 7);
  EffectsFrame near = all;
  ParticleSet& ps = near.particles[0];
  ps.position_W.clear(), ps.velocity_W.clear(), ps.radius_m.clear();
  const CameraIntrinsics& k = view.intrinsics;
  const double half_u = std::atan(0.5 * k.width / k.fx) + margin;
  const double half_v = std::atan(0.5 * k.height / k.fy) + margin;
  const Eigen::Vector3f cam = view.X_WO.translation().cast<float>();
  for (size_t i = 0; i < all.particles[0].position_W.size(); ++i) {
    const Eigen::Vector3f p = all.particles[0].position_W[i] - cam;  // camera looks along +x
    const bool close = p.norm() < close_m;
    const bool in_view = p.x() > 0 && std::abs(std::atan2(p.y(), p.x())) < half_u &&
                         std::abs(std::atan2(p.z(), p.x())) < half_v;
    if (!close && !in_view) continue;
    ps.position_W.push_back(all.particles[0].position_W[i]);
    ps.velocity_W.push_back(all.particles[0].velocity_W[i]);
    ps.radius_m.push_back(all.particles[0].radius_m[i]);
  }
  ASSERT_LT(ps.position_W.size(), 20000u);
  MediaScene media;
  media.Build(&all);
  ParticleScene a, b;
  a.Build(&all, camera, 0.01, StreakRays::kPixelCentres, nullptr, &media);
  b.Build(&near, camera, 0.01, StreakRays::kPixelCentres, nullptr, &media);
  EXPECT_EQ(a.size(), b.size());
  EXPECT_EQ(a.culled(), b.culled());
  int hits = 0;
  for (int v = 0; v < H; ++v) {
    for (int u = 0; u < W; ++u) {
      const Ray r = camera.GenerateRay(static_cast<float>(u), static_cast<float>(v));
      ParticleHit ha, hb;
      const bool x = a.PixelHit(r, u, v, 1e30f, &ha), y = b.PixelHit(r, u, v, 1e30f, &hb);
      ASSERT_EQ(x, y) << u << " " << v;
      if (!x) continue;
      ++hits;
      EXPECT_EQ(ha.prim, hb.prim);
      EXPECT_EQ(ha.t, hb.t);
      EXPECT_EQ(ha.alpha, hb.alpha);
    }
  }
  EXPECT_GT(hits, 50);
}

TEST(EffectsRebuildTest, DropsOutsideTheViewAreSkippedWithoutChangingHits) {
  ExpectSkippedDropsChangeNoHit(false);
}

TEST(EffectsRebuildTest, DropsOutsideAMovingViewAreSkippedWithoutChangingHits) {
  ExpectSkippedDropsChangeNoHit(true);
}

TEST(EffectsRebuildTest, DropJustOutsideTheImageStillCoversItsBorderPixels) {
  // a still drop whose centre projects 0.4 px beyond the left image border (pixel centre
  // column 0 is 0.9 px away) with a radius of 3 px there: outside the pyramid of the pixel
  // rays by its centre, but its capsule reaches column 0, so it is kept and drawn there.
  const int W = 64, H = 48;
  const CameraView view = MakeView(CameraLookingAlongX(), W, H, 60.0);
  const Camera camera(view.X_WO, view.intrinsics);
  const CameraIntrinsics& k = view.intrinsics;
  const double depth = 4.0, u = -0.9, v = 0.5 * (H - 1);
  EffectsFrame fx;
  ParticleSet sparks;
  sparks.kind = ParticleKind::kSpark;
  sparks.emission = Eigen::Vector3f(1, 1, 1);
  // image x = world -y, image y = world -z.
  sparks.position_W.emplace_back(depth, -(u - k.cx) / k.fx * depth, -(v - k.cy) / k.fy * depth);
  sparks.velocity_W.emplace_back(0, 0, 0);
  sparks.radius_m.push_back(static_cast<float>(3.0 * depth / k.fx));
  fx.particles.push_back(sparks);
  ParticleScene scene;
  scene.Build(&fx, camera, 0.01, StreakRays::kPixelCentres, nullptr, nullptr);
  ASSERT_EQ(scene.size(), 1);
  ParticleHit h;
  const int row = static_cast<int>(v);
  EXPECT_TRUE(scene.PixelHit(camera.GenerateRay(0, row), 0, row, 1e30f, &h));
  EXPECT_FALSE(scene.PixelHit(camera.GenerateRay(10, row), 10, row, 1e30f, &h));
}

}  // namespace
}  // namespace penumbra::testing
