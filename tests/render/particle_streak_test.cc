// particle streaks: a moving spark is drawn as a streak whose length in pixels is its
// projected motion over the exposure, with coverage 2r / (|v| T + 2r); rain and snow shading.

#include <gtest/gtest.h>

#include <cmath>

#include "media_test_util.h"
#include "penumbra/core/error.h"
#include "penumbra/render/camera.h"
#include "penumbra/render/embree/particle_scene.h"

namespace penumbra {
namespace {

using namespace penumbra::testing;

constexpr int kW = 160, kH = 120;

// renders one spark at depth `depth` moving along world -y (image +u) at speed `speed` for
// `exposure` seconds, centred on pixel row `row`; returns the lit pixel span in that row and
// writes the expected projected length.
int StreakSpan(double depth, double speed, double exposure, int row, double* expected_px,
               const ImageF** img_out = nullptr) {
  const SceneDescription s = EmptyScene();
  CameraView view = MakeView(CameraLookingAlongX(), kW, kH, 30, true, false, false);
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
  for (int u = 0; u < kW; ++u)
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
    for (bool pixel_hits : {false, true}) {
      ParticleScene scene;
      try {
        scene.Build(&fx, camera, 0.01, pixel_hits, p);
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
  scene.Build(&fx, camera, 0.01, true, &pool);
  EXPECT_EQ(scene.size() + scene.culled(), 27000);
}

}  // namespace
}  // namespace penumbra
