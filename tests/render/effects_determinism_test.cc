// determinism of effects rendering: identical EffectsFrames give bit-identical images for any
// thread count; the seed changes the image when media are present; clear / empty effects
// leave images exactly as without effects.

#include <gtest/gtest.h>

#include <cmath>

#include "render/media_test_util.h"

namespace penumbra {
namespace {

using namespace penumbra::testing;

// a lit room corner: floor, back wall, a sphere, a point light, a uniform sky.
SceneDescription LitScene() {
  SceneDescription s = EmptyScene();
  s.sky.radiance = Eigen::Vector3f(0.3f, 0.35f, 0.4f);
  const int grey = AddMaterial(&s, Eigen::Vector3f(0.6f, 0.6f, 0.6f), 0.6f, 0.0f, 0.5f);
  const int red = AddMaterial(&s, Eigen::Vector3f(0.7f, 0.2f, 0.1f), 0.3f, 0.0f, 0.5f);
  AddGeom(&s, GeomShape::kPlane, {0, 0, 1}, Translation(0, 0, -1), 0, grey);
  AddGeom(&s, GeomShape::kBox, {0.05, 3, 3}, Translation(6, 0, 0), 0, grey);
  AddGeom(&s, GeomShape::kSphere, {0.5, 0, 0}, Translation(3, 0.5, -0.5), 0, red);
  Light l;
  l.type = Light::Type::kPoint;
  l.position_B = Eigen::Vector3d(2, -1, 1.5);
  l.intensity = 50;
  l.radius_m = 0.05f;
  s.lights.push_back(l);
  return s;
}

// fog + a smoke grid + rain + sparks.
EffectsFrame Adverse() {
  EffectsFrame fx;
  HomogeneousMedium fog = Fog(0.15f, 0.9f, 0.3f);
  fog.height_falloff_per_m = 0.2f;
  fx.homogeneous_media.push_back(fog);
  GridMedium g = RampGrid({2.5, -0.5, 0}, {0.6, 0.6, 0.6}, 8, 1.0f, 0.8f, 2.0f, 0.8f);
  fx.grid_media.push_back(g);
  ParticleSet rain;
  rain.kind = ParticleKind::kRain;
  rain.color = Eigen::Vector3f(0.9f, 0.9f, 1.0f);
  ParticleSet sparks;
  sparks.kind = ParticleKind::kSpark;
  sparks.emission = Eigen::Vector3f(20, 8, 2);
  for (int i = 0; i < 300; ++i) {
    const float x = 1.0f + 0.015f * i, y = -1.5f + 0.01f * ((i * 37) % 300),
                z = -0.9f + 0.006f * ((i * 53) % 300);
    rain.position_W.emplace_back(x, y, z);
    rain.velocity_W.emplace_back(0, 0.5f, -8);
    rain.radius_m.push_back(0.002f);
    if (i % 10 == 0) {
      sparks.position_W.emplace_back(x, -y, z);
      sparks.velocity_W.emplace_back(0.3f, 0, 2);
      sparks.radius_m.push_back(0.005f);
    }
  }
  fx.particles = {rain, sparks};
  fx.surface_wetness = 0.5f;
  return fx;
}

RenderedFrame Render(const SceneDescription& s, const EffectsFrame* fx, RenderSettings::Tier tier,
                     int threads, uint64_t seed) {
  RenderSettings rs = TierSettings(tier, 4, threads);
  rs.seed = seed;
  auto r = MakeRenderer(s, rs);
  CameraView view = MakeView(CameraLookingAlongX(), 64, 48, 60, true, true, true);
  view.exposure_time_sec = 0.02;
  RenderedFrame f;
  r->Render(IdentitySnapshot(s), fx, view, &f);
  return f;
}

TEST(EffectsDeterminismTest, SameEffectsSameImageAnyThreadCount) {
  const SceneDescription s = LitScene();
  const EffectsFrame adverse = Adverse();
  const EffectsFrame* fx = &adverse;
  for (RenderSettings::Tier tier :
       {RenderSettings::Tier::kRealtime, RenderSettings::Tier::kPathtraced}) {
    const RenderedFrame a = Render(s, fx, tier, 1, 3);
    const RenderedFrame b = Render(s, fx, tier, 1, 3);
    const RenderedFrame c = Render(s, fx, tier, 3, 3);
    EXPECT_EQ(a.radiance.data, b.radiance.data);
    EXPECT_EQ(a.radiance.data, c.radiance.data);
    EXPECT_EQ(a.rgb.data, c.rgb.data);
    for (float x : a.radiance.data) ASSERT_TRUE(std::isfinite(x));
    // a different seed gives a different image (media are sampled per pixel stream).
    const RenderedFrame d = Render(s, fx, tier, 1, 4);
    EXPECT_NE(a.radiance.data, d.radiance.data);
    // and the effects change the image at all.
    const RenderedFrame clear = Render(s, nullptr, tier, 1, 3);
    EXPECT_NE(a.radiance.data, clear.radiance.data);
  }
}

TEST(EffectsDeterminismTest, NullOrEmptyEffectsLeaveImagesUnchanged) {
  const SceneDescription s = LitScene();
  for (RenderSettings::Tier tier :
       {RenderSettings::Tier::kRealtime, RenderSettings::Tier::kPathtraced}) {
    const EffectsFrame empty_fx;
    const RenderedFrame none = Render(s, nullptr, tier, 2, 1);
    const RenderedFrame empty = Render(s, &empty_fx, tier, 2, 1);
    EffectsFrame no_particles;  // a particle set without particles: active, draws nothing
    no_particles.particles.emplace_back();
    const RenderedFrame hollow = Render(s, &no_particles, tier, 2, 1);
    EXPECT_EQ(none.radiance.data, empty.radiance.data);
    EXPECT_EQ(none.rgb.data, empty.rgb.data);
    EXPECT_EQ(none.radiance.data, hollow.radiance.data);
    EXPECT_EQ(none.depth_m.data, hollow.depth_m.data);
    EXPECT_EQ(none.geom_id.data, hollow.geom_id.data);
  }
}

}  // namespace
}  // namespace penumbra
