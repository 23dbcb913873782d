// particle streaks: a moving spark is drawn as a streak whose length in pixels is its
// projected motion over the exposure, with coverage 2r / (|v| T + 2r); rain and snow shading.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "penumbra/core/error.h"
#include "penumbra/render/camera/camera.h"
#include "penumbra/render/embree/particle_scene.h"
#include "penumbra/render/particles/particle_math.h"
#include "penumbra/render/particles/particle_streaks.h"
#include "render/media_test_util.h"

namespace penumbra {
namespace {

using namespace penumbra::testing;

constexpr int kStreakW = 160, kStreakH = 120;

// renders one spark at depth `depth` moving along world -y (image +u) at speed `speed` for
// `exposure` seconds, centred on pixel row `row`; returns the lit pixel span in that row and
// writes the expected projected length.
int StreakSpan(double depth, double speed, double exposure, int row, double* expected_px,
               const ImageF** img_out = nullptr) {
  const SceneDescription s = EmptyScene();
  CameraView view = MakeView(CameraLookingAlongX(), kStreakW, kStreakH, 30, true, false, false);
  view.exposure_time_sec = exposure;
  const CameraIntrinsics& k = view.intrinsics;
  // world point seen at pixel (u0, row): image x = world -y, image y = world -z.
  const double u0 = 40;
  const double y = -(u0 - k.cx) / k.fx * depth, z = -(row - k.cy) / k.fy * depth;
  EffectsFrame fx;
  ParticleSet sparks;
  sparks.kind = ParticleKind::kSpark;
  sparks.emission = Eigen::Vector3f(5, 5, 5);
  sparks.position_W.emplace_back(depth, y, z);
  sparks.velocity_W.emplace_back(0, -speed, 0);
  sparks.radius_m.push_back(1e-5f);  // far below a pixel: widened to half a pixel
  fx.particles.push_back(sparks);
  auto r = MakeRenderer(s, TierSettings(RenderSettings::Tier::kRealtime));
  static RenderedFrame f;
  r->Render(IdentitySnapshot(s), &fx, view, &f);
  if (img_out) *img_out = &f.radiance;
  *expected_px = k.fx * speed * exposure / depth;
  int first = -1, last = -1;
  for (int u = 0; u < kStreakW; ++u)
    if (f.radiance.at(u, row)[1] > 0) {
      if (first < 0) first = u;
      last = u;
    }
  return first < 0 ? -1 : last - first;
}

TEST(ParticleStreakTest, StreakLengthIsProjectedMotion) {
  for (auto [depth, speed, exposure] :
       {std::tuple{4.0, 10.0, 0.02}, {2.5, 6.0, 0.01}, {6.0, 30.0, 0.015}}) {
    double expected;
    const int span = StreakSpan(depth, speed, exposure, 60, &expected);
    ASSERT_GE(span, 0);
    EXPECT_NEAR(span, expected, 1.0) << "depth " << depth << " speed " << speed;
    RecordProperty("span_px_vs_expected_" + std::to_string(static_cast<int>(expected)),
                   std::to_string(span) + " / " + std::to_string(expected));
  }
}

TEST(ParticleStreakTest, CoverageFollowsExposureFraction) {
  // a streak wider than a pixel: coverage 2r / (|v| T + 2r), so the pixel shows alpha Le.
  const SceneDescription s = EmptyScene();
  CameraView view = MakeView(CameraLookingAlongX(), 64, 48, 30, true, false, false);
  view.exposure_time_sec = 0.01;
  EffectsFrame fx;
  ParticleSet sparks;
  sparks.kind = ParticleKind::kSpark;
  sparks.emission = Eigen::Vector3f(4, 4, 4);
  const float r = 0.02f, v = 20.0f;
  sparks.position_W.emplace_back(3, 0.1f, 0);
  sparks.velocity_W.emplace_back(0, -v, 0);  // through the centre of the view
  sparks.radius_m.push_back(r);
  fx.particles.push_back(sparks);
  auto rr = MakeRenderer(s, TierSettings(RenderSettings::Tier::kRealtime));
  RenderedFrame f;
  rr->Render(IdentitySnapshot(s), &fx, view, &f);
  const double alpha = 2 * r / (v * 0.01 + 2 * r);
  EXPECT_NEAR(f.radiance.at(32, 23)[1], 4 * alpha, 1e-4);
  // a still particle covers fully.
  fx.particles[0].velocity_W[0].setZero();
  fx.particles[0].position_W[0] = Eigen::Vector3f(3, 0, 0);
  fx.particles[0].radius_m[0] = 0.05f;
  rr->Render(IdentitySnapshot(s), &fx, view, &f);
  EXPECT_NEAR(f.radiance.at(32, 23)[1], 4.0, 1e-4);
}

TEST(ParticleStreakTest, RainAndSnowShading) {
  SceneDescription s = EmptyScene();
  s.sky.radiance = Eigen::Vector3f(0.5f, 0.5f, 0.5f);
  CameraView view = MakeView(CameraLookingAlongX(), 64, 48, 30, true, false, false);
  view.exposure_time_sec = 0;
  for (ParticleKind kind : {ParticleKind::kRain, ParticleKind::kSnow}) {
    EffectsFrame fx;
    ParticleSet p;
    p.kind = kind;
    p.color = Eigen::Vector3f(0.8f, 0.8f, 0.8f);
    p.position_W.emplace_back(3, 0, 0);
    p.velocity_W.emplace_back(0, 0, -5);
    p.radius_m.push_back(0.05f);
    fx.particles.push_back(p);
    auto rr = MakeRenderer(s, TierSettings(RenderSettings::Tier::kRealtime));
    RenderedFrame f;
    rr->Render(IdentitySnapshot(s), &fx, view, &f);
    // no lights: colour x sphere-average sky radiance (uniform sky, within the 1 % of the
    // irradiance table), over the sky behind it.
    EXPECT_NEAR(f.radiance.at(32, 23)[1], 0.8 * 0.5, 0.01) << static_cast<int>(kind);
  }
}

// uniform floats in [0, 1) from a 64-bit linear congruential generator (Knuth's MMIX constants).
struct Lcg {
  uint64_t state;
  float operator()() {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<float>(state >> 40) / static_cast<float>(1 << 24);
  }
};

// `view`'s camera still, and during a rolling-shutter readout (row 0 at 2 ms, line_time_sec per
// row) in which it turns by `angle` (rad) about `axis` (world) and moves by `move` (m) in 30 ms.
std::vector<Camera> StillAndRollingCameras(const CameraView& view, double line_time_sec,
                                           double angle, const Eigen::Vector3d& axis,
                                           const Eigen::Vector3d& move) {
  CameraMotion motion;
  motion.end_sec = 0.03;
  motion.time_sec = 0.002;
  motion.line_time_sec = line_time_sec;
  motion.X_WO_end = view.X_WO;
  motion.X_WO_end.linear() =
      Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix() * view.X_WO.linear();
  motion.X_WO_end.translation() += move;
  return {Camera(view.X_WO, view.intrinsics), Camera(view.X_WO, view.intrinsics, motion)};
}

// the first non-finite particle in (set, index) order is reported, whatever the thread count
// (the check runs in the parallel chunks of Build).
TEST(ParticleSceneTest, FirstNonFiniteParticleIsReported) {
  EffectsFrame fx;
  for (int s = 0; s < 3; ++s) {
    ParticleSet ps;
    for (int i = 0; i < 9000; ++i) {
      ps.position_W.emplace_back(5.0f + 0.001f * i, 0.1f * s, 0.0f);
      ps.velocity_W.emplace_back(0.0f, 0.0f, -5.0f);
      ps.radius_m.push_back(0.001f);
    }
    fx.particles.push_back(ps);
  }
  fx.particles[1].velocity_W[8500].y() = NAN;
  fx.particles[1].radius_m[6000] = INFINITY;
  fx.particles[2].position_W[10].x() = NAN;
  const CameraView view = MakeView(CameraLookingAlongX(), 64, 48, 60.0);
  const Camera camera(view.X_WO, view.intrinsics);
  ThreadPool pool(2);
  for (ThreadPool* p : {static_cast<ThreadPool*>(nullptr), &pool}) {
    for (StreakRays rays : {StreakRays::kAny, StreakRays::kCamera, StreakRays::kPixelCentres}) {
      ParticleScene scene;
      try {
        scene.Build(&fx, camera, 0.01, rays, p);
        ADD_FAILURE() << "expected a ConfigError";
      } catch (const ConfigError& e) {
        EXPECT_EQ(e.key(), "effects.particles[1]");
        EXPECT_NE(std::string(e.what()).find("particle 6000 has a non-finite value"),
                  std::string::npos)
            << e.what();
      }
    }
  }
  // valid again: builds.
  fx.particles[1].velocity_W[8500].y() = 0;
  fx.particles[1].radius_m[6000] = 0.001f;
  fx.particles[2].position_W[10].x() = 5;
  ParticleScene scene;
  scene.Build(&fx, camera, 0.01, StreakRays::kPixelCentres, &pool);
  EXPECT_EQ(scene.size() + scene.culled(), 27000);
}

// the camera's rays (StreakRays::kCamera, the pathtraced tier's jittered samples) meet the
// same nearest streak whether the drops outside the view pyramid were left out or not: a
// still and a moving camera (turning and travelling during a rolling-shutter readout), rays
// through random points of the image and along its edges and corners.
TEST(ParticleSceneTest, CameraRaysMeetEveryStreakTheyWouldWithoutTheViewCull) {
  EffectsFrame fx;
  Lcg uniform{12345};
  // drops all around the camera (at the origin), 0.3 to 6 m away, some large and slow.
  for (ParticleKind kind : {ParticleKind::kRain, ParticleKind::kSnow}) {
    ParticleSet ps;
    ps.kind = kind;
    for (int i = 0; i < 20000; ++i) {
      const float r = 0.3f + 5.7f * uniform();
      Eigen::Vector3f dir(2 * uniform() - 1, 2 * uniform() - 1, 2 * uniform() - 1);
      if (!(dir.norm() > 1e-3f)) dir = Eigen::Vector3f(1, 0, 0);
      ps.position_W.push_back(r * dir.normalized());
      ps.velocity_W.emplace_back(uniform() - 0.5f, uniform() - 0.5f, -2 - 6 * uniform());
      ps.radius_m.push_back(i % 50 == 0 ? 0.05f : 0.0005f + 0.002f * uniform());
    }
    fx.particles.push_back(ps);
  }
  const CameraView view = MakeView(CameraLookingAlongX(), 64, 48, 60.0);
  const int W = view.intrinsics.width, H = view.intrinsics.height;
  for (const Camera& camera : StillAndRollingCameras(
           view, 0.0004, 0.3, Eigen::Vector3d(0.2, 1, 0.1), Eigen::Vector3d(0.1, -0.2, 0.05))) {
    ParticleScene all, seen;
    all.Build(&fx, camera, 0.01, StreakRays::kAny);
    seen.Build(&fx, camera, 0.01, StreakRays::kCamera);
    // most drops lie outside the view (a 60 x 80 degree pyramid of the whole sphere).
    EXPECT_LT(seen.size(), all.size() / 3) << "moving " << camera.motion().moving();
    int hits = 0;
    auto check = [&](float u, float v) {
      const Ray ray = camera.GenerateRay(u, v);
      ParticleHit a, b;
      const bool ha = all.Intersect(ray, 1e9f, &a), hb = seen.Intersect(ray, 1e9f, &b);
      ASSERT_EQ(ha, hb) << "ray through (" << u << ", " << v << ")";
      if (!ha) return;
      ++hits;
      EXPECT_EQ(a.t, b.t);
      EXPECT_EQ(all.ends()[2 * a.prim], seen.ends()[2 * b.prim]);
    };
    for (int i = 0; i < 200000; ++i) check(W * uniform() - 0.5f, H * uniform() - 0.5f);
    // the image's edges and corners (u = -0.5, W - 0.5; v = -0.5, H - 0.5).
    for (int i = 0; i <= 4000; ++i) {
      const float a = static_cast<float>(i) / 4000;
      check(-0.5f, H * a - 0.5f);
      check(W - 0.5f, H * a - 0.5f);
      check(W * a - 0.5f, -0.5f);
      check(W * a - 0.5f, H - 0.5f);
    }
    EXPECT_GT(hits, 5000) << "moving " << camera.motion().moving();
  }
}

// the realtime splat of a rolling-shutter camera that turns and travels during the readout
// (ParticleStreaks::Build with kPixelCentres, the CPU backend's realtime streaks): every pixel
// whose pixel-centre ray, cast with its own row's pose (Camera::GenerateRay), meets a streak's
// capsule gets the nearest such streak (brute force over every streak: the same streak and t),
// and no other pixel has one. a splat that takes every streak's box and row columns in the
// first row's pose only, without widening the boxes for the rows' motion, would leave out 206 of
// the 344 pixels met here (counted below, so the check can fail). a still camera is checked too.
TEST(ParticleStreakTest, RollingShutterSplatFindsEveryStreakItsRowsMeet) {
  EffectsFrame fx;
  Lcg uniform{777};
  // rain 0.5 to 6 m ahead of the camera (at the origin, looking along +x), spread over a
  // cone wider than the view so that the turn brings drops into the lower rows.
  ParticleSet rain;
  rain.kind = ParticleKind::kRain;
  for (int i = 0; i < 600; ++i) {
    const float d = 0.5f + 5.5f * uniform();
    rain.position_W.emplace_back(d, d * (2.4f * uniform() - 1.2f), d * (1.6f * uniform() - 0.8f));
    rain.velocity_W.emplace_back(0.3f * (uniform() - 0.5f), 0.3f * (uniform() - 0.5f), -5.0f);
    rain.radius_m.push_back(0.001f + 0.002f * uniform());
  }
  fx.particles.push_back(rain);
  const CameraView view = MakeView(CameraLookingAlongX(), 64, 48, 60.0);
  const int W = view.intrinsics.width, H = view.intrinsics.height;
  for (const Camera& camera : StillAndRollingCameras(
           view, 0.0006, 0.25, Eigen::Vector3d(0.3, 0.2, 1), Eigen::Vector3d(0.1, -0.15, 0.05))) {
    SCOPED_TRACE(camera.motion().moving() ? "moving camera" : "still camera");
    ParticleStreaks streaks;
    streaks.Build(&fx, camera, 0.01, StreakRays::kPixelCentres);
    ASSERT_GT(streaks.size(), 100);
    // the first row's pose only (X_WO: boxes and row columns not widened for the rows' motion),
    // to show that the check can fail: the pixels met by a streak outside its box there
    const Pose X_OW = camera.X_WO().inverse();
    const Eigen::Matrix<float, 3, 3, Eigen::RowMajor> R_OW = X_OW.linear().cast<float>();
    const Eigen::Vector3f p_OW = X_OW.translation().cast<float>();
    const CameraIntrinsics& k = view.intrinsics;
    const auto in_first_pose_box = [&](int n, int u, int v) {
      const Eigen::Vector4f& a = streaks.ends()[2 * n];
      const Eigen::Vector4f& b = streaks.ends()[2 * n + 1];
      const Float3 po{p_OW.x(), p_OW.y(), p_OW.z()};
      const StreakProjection q =
          ProjectStreak(StreakToOptical(R_OW.data(), po, Float3{a.x(), a.y(), a.z()}),
                        StreakToOptical(R_OW.data(), po, Float3{b.x(), b.y(), b.z()}), a.w(), k.fx,
                        k.fy, k.cx, k.cy, W, H);
      if (q.empty() || v < q.v0 || v > q.v1) return false;
      int c0, c1;
      StreakRowColumns(q, v, &c0, &c1);
      return c0 <= u && u <= c1;
    };
    int met = 0, missed = 0, other = 0, outside_first_pose = 0;
    for (int v = 0; v < H; ++v) {
      for (int u = 0; u < W; ++u) {
        const Ray ray = camera.GenerateRay(static_cast<float>(u), static_cast<float>(v));
        const Float3 o{ray.o.x(), ray.o.y(), ray.o.z()}, d{ray.d.x(), ray.d.y(), ray.d.z()};
        // the nearest streak (ties: the lower index) by brute force
        float t_best = std::numeric_limits<float>::infinity();
        int best = -1;
        for (int n = 0; n < streaks.size(); ++n) {
          const Eigen::Vector4f& a = streaks.ends()[2 * n];
          const Eigen::Vector4f& b = streaks.ends()[2 * n + 1];
          const float t = IntersectCapsuleRay(
              MakeCapsuleOrigin(o, Float3{a.x(), a.y(), a.z()}, Float3{b.x(), b.y(), b.z()}, a.w()),
              d);
          if (t > 0 && t < t_best) {
            t_best = t;
            best = n;
          }
        }
        ParticleHit hit;
        const bool has = streaks.PixelHit(ray, u, v, std::numeric_limits<float>::infinity(), &hit);
        if (best < 0) {
          other += has ? 1 : 0;
          continue;
        }
        ++met;
        outside_first_pose += in_first_pose_box(best, u, v) ? 0 : 1;
        if (!has) {
          ++missed;
          continue;
        }
        EXPECT_EQ(hit.prim, best) << "pixel (" << u << ", " << v << ")";
        EXPECT_EQ(hit.t, t_best) << "pixel (" << u << ", " << v << ")";
      }
    }
    std::printf(
        "%s: %d streaks, %d pixels meet one (brute force), %d of them missed by the "
        "splat, %d others keyed; %d outside their streak's box in the first row's pose\n",
        camera.motion().moving() ? "rolling shutter, moving" : "still", streaks.size(), met, missed,
        other, outside_first_pose);
    EXPECT_GT(met, 300);
    EXPECT_EQ(missed, 0);
    EXPECT_EQ(other, 0);
    if (camera.motion().moving())
      EXPECT_GT(outside_first_pose, met / 4);
    else
      EXPECT_EQ(outside_first_pose, 0);
  }
}

}  // namespace
}  // namespace penumbra
