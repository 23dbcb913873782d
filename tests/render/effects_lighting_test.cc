// lighting events of an EffectsFrame: per-light intensity scale, extra lights, sky luminance
// scale, a moved sun, surface wetness; both tiers where cheap.

#include <gtest/gtest.h>

#include <cmath>

#include "penumbra/render/material/material_eval.h"
#include "penumbra/render/sky/sky_model.h"
#include "render/media_test_util.h"

namespace penumbra {
namespace {

using namespace penumbra::testing;

// a Lambertian floor (albedo 0.5) under a 1000 lx overhead sun, seen from 2 m above.
SceneDescription SunFloor() {
  SceneDescription s = EmptyScene();
  const int m = AddMaterial(&s, Eigen::Vector3f::Constant(0.5f), 1.0f, 0.0f, 0.0f);
  AddGeom(&s, GeomShape::kPlane, {0, 0, 1}, Pose::Identity(), 0, m);
  Light sun;
  sun.type = Light::Type::kDirectional;
  sun.direction_B = Eigen::Vector3d(0, 0, -1);
  sun.intensity = 1000;
  s.lights.push_back(sun);
  return s;
}

double CentreRadiance(const SceneDescription& s, const EffectsFrame* fx,
                      RenderSettings::Tier tier = RenderSettings::Tier::kRealtime) {
  auto r = MakeRenderer(s, TierSettings(tier, 16));
  const CameraView view = MakeView(CameraLookingDown({0, 0, 2}), 9, 9, 20, true, false, false);
  RenderedFrame f;
  r->Render(IdentitySnapshot(s), fx, view, &f);
  return f.radiance.at(4, 4)[1];
}

TEST(EffectsLightingTest, IntensityScaleAndExtraLights) {
  const SceneDescription s = SunFloor();
  const double base = CentreRadiance(s, nullptr);
  EXPECT_NEAR(base, 1000 * 0.5 / M_PI, 0.01 * base);
  EffectsFrame fx;
  fx.light_intensity_scale = {0.25f};
  EXPECT_NEAR(CentreRadiance(s, &fx), 0.25 * base, 1e-3 * base);
  // blackout plus a flashlight: a spot 1 m above the floor pointing down, 200 cd on its axis.
  fx.light_intensity_scale = {0.0f};
  Light spot;
  spot.type = Light::Type::kSpot;
  spot.position_B = Eigen::Vector3d(0, 0, 1);
  spot.direction_B = Eigen::Vector3d(0, 0, -1);
  spot.intensity = 200;
  fx.extra_lights.push_back(spot);
  for (RenderSettings::Tier tier :
       {RenderSettings::Tier::kRealtime, RenderSettings::Tier::kPathtraced}) {
    const double L = CentreRadiance(s, &fx, tier);
    EXPECT_NEAR(L, 200 * 0.5 / M_PI, 0.02 * 200 * 0.5 / M_PI);
  }
}

TEST(EffectsLightingTest, WetnessDarkensUpwardSurfaces) {
  const SceneDescription s = SunFloor();
  const double dry = CentreRadiance(s, nullptr);
  EffectsFrame fx;
  fx.surface_wetness = 1.0f;
  // fully rough: only the albedo changes (x 0.3).
  EXPECT_NEAR(CentreRadiance(s, &fx), 0.3 * dry, 1e-3 * dry);
  PbrParams p;
  p.base_color = Eigen::Vector3f::Constant(0.5f);
  p.roughness = 0.6f;
  ApplySurfaceWetness(1.0f, Eigen::Vector3f(1, 0, 0), &p);  // a wall stays dry
  EXPECT_FLOAT_EQ(p.roughness, 0.6f);
  ApplySurfaceWetness(1.0f, Eigen::Vector3f(0, 0, 1), &p);
  EXPECT_NEAR(p.roughness, 0.0f, 1e-6);  // gloss 0.4 x 2.5 = 1
  EXPECT_NEAR(p.base_color.x(), 0.15f, 1e-6);
}

TEST(EffectsLightingTest, SkyScaleAndMovedSun) {
  SceneDescription s = EmptyScene();
  s.sky.type = Sky::Type::kDaylight;
  s.sky.sun_direction_W = Eigen::Vector3d(0.3, 0.2, 0.93);
  // look at the horizon towards +x.
  auto r = MakeRenderer(s, TierSettings(RenderSettings::Tier::kRealtime));
  const CameraView view = MakeView(CameraLookingAlongX(), 9, 9, 10, true, false, false);
  RenderedFrame f;
  r->Render(IdentitySnapshot(s), view, &f);
  const double base = f.radiance.at(4, 4)[1];
  EffectsFrame fx;
  fx.sky_luminance_scale = 0.1f;
  r->Render(IdentitySnapshot(s), &fx, view, &f);
  EXPECT_NEAR(f.radiance.at(4, 4)[1], 0.1 * base, 1e-3 * base);
  // the sun moves to just above the horizon in +x: the sky there brightens as the model says.
  fx.sky_luminance_scale = 1.0f;
  fx.sun_direction_W = Eigen::Vector3d(1, 0, 0.2).normalized();
  r->Render(IdentitySnapshot(s), &fx, view, &f);
  Sky moved = s.sky;
  moved.sun_direction_W = *fx.sun_direction_W;
  const Eigen::Vector3f expected = SkyModel(moved).Radiance(Eigen::Vector3f(1, 0, 0));
  EXPECT_NEAR(f.radiance.at(4, 4)[1], expected.y(), 1e-3 * expected.y());
  EXPECT_GT(expected.y(), base);
  // back to no effects: the original sky.
  r->Render(IdentitySnapshot(s), view, &f);
  EXPECT_EQ(f.radiance.at(4, 4)[1], static_cast<float>(base));
}

}  // namespace
}  // namespace penumbra
