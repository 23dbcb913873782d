// EffectsEngine: media, fire glow, smoke determinism, flashlight, sun, wetness, config errors.
#include "penumbra/effects/effects_engine.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "penumbra/core/error.h"
#include "penumbra/effects/blackbody.h"
#include "penumbra/effects/sun.h"

namespace penumbra {
namespace {

EffectConfig Fog() {
  EffectConfig e;
  e.name = "fog";
  e.params = FogParams{};
  e.Get<FogParams>().extinction.mor_m = 50;
  e.start_sec = 1;
  e.stop_sec = 9;
  e.fade_in_sec = 2;
  return e;
}

// an unbounded fog is a layer: its top defaults to the top of the model's bounding sphere,
// layer_top_m overrides it, a region replaces it.
TEST(EffectsEngineTest, UnboundedFogIsALayerWithATop) {
  SceneDescription scene;
  scene.center_W = Eigen::Vector3d(1, 2, 0.5);
  scene.extent_m = 4;
  {
    EffectsEngine engine({Fog()}, 1, scene);
    auto f = engine.Evaluate(5.0, {0, 0, 0});
    ASSERT_EQ(f->homogeneous_media.size(), 1u);
    EXPECT_FLOAT_EQ(f->homogeneous_media[0].layer_top_m, 4.5f);
  }
  EffectConfig top = Fog();
  top.Get<FogParams>().layer_top_m = 30;
  EffectConfig boxed = Fog();
  boxed.name = "boxed";
  boxed.region = BoxRegion{{0, 0, 0}, {1, 1, 1}};
  EffectsEngine engine({top, boxed}, 1, scene);
  auto f = engine.Evaluate(5.0, {0, 0, 0});
  ASSERT_EQ(f->homogeneous_media.size(), 2u);
  EXPECT_FLOAT_EQ(f->homogeneous_media[0].layer_top_m, 30.0f);
  EXPECT_TRUE(std::isinf(f->homogeneous_media[1].layer_top_m));
  top.Get<FogParams>().layer_top_m = std::numeric_limits<double>::infinity();
  EXPECT_EQ(top.Validate()->key, "layer_top_m");
}

TEST(EffectsEngineTest, EmptyConfigGivesAnEmptyFrame) {
  EffectsEngine engine({}, 1, SceneDescription{});
  auto f = engine.Evaluate(3.0, {0, 0, 0});
  EXPECT_TRUE(f->empty());
  EXPECT_EQ(f->time_sec, 3.0);
}

TEST(EffectsEngineTest, FogFromMorWithFadeIn) {
  EffectsEngine engine({Fog()}, 1, SceneDescription{});
  EXPECT_TRUE(engine.Evaluate(0.5, {0, 0, 0})->homogeneous_media.empty());
  auto f = engine.Evaluate(2.0, {0, 0, 0});  // halfway through the fade
  ASSERT_EQ(f->homogeneous_media.size(), 1u);
  // Koschmieder: sigma_t = -ln(0.05) / MOR
  EXPECT_NEAR(f->homogeneous_media[0].sigma_t_per_m.x(), 0.5 * 2.9957 / 50, 1e-5);
  auto g = engine.Evaluate(5.0, {0, 0, 0});
  EXPECT_NEAR(g->homogeneous_media[0].sigma_t_per_m.x(), 2.9957 / 50, 1e-5);
  EXPECT_FLOAT_EQ(g->homogeneous_media[0].g, 0.8f);
}

EffectConfig Smoke(SmokeParams::Mode mode) {
  EffectConfig e;
  e.name = "smoke";
  e.params = SmokeParams{};
  e.region = BoxRegion{{-1, -1, 0}, {1, 1, 2}};
  e.Get<SmokeParams>().mode = mode;
  e.Get<SmokeParams>().noise_resolution = 16;
  e.Get<SmokeParams>().fluid.resolution = 16;
  PlumeEmitter em;
  em.position_W = {0, 0, 0.3};
  e.Get<SmokeParams>().fluid.emitters = {em};
  e.Get<SmokeParams>().wind_m_s =
      mode == SmokeParams::Mode::kPlume ? Eigen::Vector3d::Zero() : Eigen::Vector3d(0.5, 0, 0);
  return e;
}

TEST(EffectsEngineTest, SmokeIsDeterministicPerSeedAndRestartsWhenTimeGoesBack) {
  for (auto mode : {SmokeParams::Mode::kNoise, SmokeParams::Mode::kPlume}) {
    EffectsEngine a({Smoke(mode)}, 10, SceneDescription{});
    EffectsEngine b({Smoke(mode)}, 10, SceneDescription{});
    EffectsEngine c({Smoke(mode)}, 11, SceneDescription{});
    std::vector<float> da, db, dc;
    for (double t : {0.2, 0.5, 1.0}) {
      da = *a.Evaluate(t, {0, 0, 0})->grid_media.at(0).density;
      db = *b.Evaluate(t, {0, 0, 0})->grid_media.at(0).density;
      dc = *c.Evaluate(t, {0, 0, 0})->grid_media.at(0).density;
    }
    EXPECT_EQ(da, db);
    EXPECT_NE(da, dc);
    for (float d : da) ASSERT_GE(d, 0.0f);
    // b jumps straight to 1.0 after going back to 0.3: same state as a at 1.0
    EffectsEngine d({Smoke(mode)}, 10, SceneDescription{});
    d.Evaluate(1.0, {0, 0, 0});
    d.Evaluate(0.3, {0, 0, 0});
    EXPECT_EQ(*d.Evaluate(1.0, {0, 0, 0})->grid_media.at(0).density, da);
  }
}

TEST(EffectsEngineTest, FireEmitsBlackbodyLightAndItsGlowMatchesTheEmittedPower) {
  EffectConfig e;
  e.name = "fire";
  e.params = FireParams{};
  e.region = BoxRegion{{-0.5, -0.5, 0}, {0.5, 0.5, 1.5}};
  e.Get<FireParams>().fluid.resolution = 16;
  PlumeEmitter em;
  em.position_W = {0, 0, 0.15};
  em.radius_m = 0.15;
  em.rate = 0.3;
  em.temperature_k = 1500;
  e.Get<FireParams>().fluid.emitters = {em};
  EffectsEngine engine({e}, 3, SceneDescription{});
  std::vector<float> intensities;
  for (double t = 0.5; t <= 2.0; t += 0.25) {
    auto f = engine.Evaluate(t, {0, 0, 0});
    ASSERT_EQ(f->grid_media.size(), 1u);
    const GridMedium& g = f->grid_media[0];
    ASSERT_TRUE(g.emission);
    ASSERT_EQ(f->extra_lights.size(), 1u);
    const Light& l = f->extra_lights[0];
    // documented relation: Y(colour) x intensity = sum of emitted luminance x voxel volume
    const double dv = (2 * g.half_extents_m).prod() / (g.nx * g.ny * g.nz);
    double sum_y = 0;
    Eigen::Vector3d sum_rgb = Eigen::Vector3d::Zero();
    for (size_t v = 0; v < g.emission->size() / 3; ++v) {
      const Eigen::Vector3d c((*g.emission)[3 * v], (*g.emission)[3 * v + 1],
                              (*g.emission)[3 * v + 2]);
      sum_y += LinearSrgbLuminance(c) * dv;
      sum_rgb += c;
    }
    EXPECT_NEAR(l.intensity * LinearSrgbLuminance(l.color.cast<double>()), sum_y, 1e-3 * sum_y);
    // flame colours: red > green > blue
    EXPECT_GT(sum_rgb.x(), sum_rgb.y());
    EXPECT_GT(sum_rgb.y(), sum_rgb.z());
    EXPECT_GT(l.position_B.z(), 0.1);
    intensities.push_back(l.intensity);
  }
  // it flickers: the glow changes from frame to frame
  const auto [lo, hi] = std::minmax_element(intensities.begin(), intensities.end());
  EXPECT_GT(*hi, *lo * 1.01);
}

TEST(EffectsEngineTest, FlashlightFollowsWaypointsOrItsBody) {
  EffectConfig e;
  e.name = "torch";
  e.params = FlashlightParams{};
  e.Get<FlashlightParams>().waypoints = {{0, {0, 0, 1}, {1, 0, 0}}, {2, {2, 0, 1}, {0, 1, 0}}};
  EffectsEngine engine({e}, 1, SceneDescription{});
  auto f = engine.Evaluate(1.0, {0, 0, 0});
  ASSERT_EQ(f->extra_lights.size(), 1u);
  const Light& l = f->extra_lights[0];
  EXPECT_EQ(l.type, Light::Type::kSpot);
  EXPECT_NEAR((l.position_B - Eigen::Vector3d(1, 0, 1)).norm(), 0, 1e-12);
  EXPECT_NEAR((l.direction_B - Eigen::Vector3d(1, 1, 0).normalized()).norm(), 0, 1e-12);
  EXPECT_FLOAT_EQ(l.intensity, 300.0f);

  SceneDescription scene;
  scene.bodies.resize(2);
  scene.bodies[1].name = "robot/base";
  EffectConfig a;
  a.name = "head";
  a.params = FlashlightParams{};
  a.Get<FlashlightParams>().attach = "robot/base";
  a.Get<FlashlightParams>().position_B = {0.2, 0, 0.1};
  a.Get<FlashlightParams>().direction_B = {1, 0, 0};
  EffectsEngine attached({a}, 1, scene);
  std::vector<Pose> X_WB(2, Pose::Identity());
  X_WB[1] = PoseFromXyzRpyDeg({1, 2, 0}, {0, 0, 90});
  auto g = attached.Evaluate(0.0, {0, 0, 0}, &X_WB);
  EXPECT_NEAR((g->extra_lights[0].position_B - Eigen::Vector3d(1, 2.2, 0.1)).norm(), 0, 1e-12);
  EXPECT_NEAR((g->extra_lights[0].direction_B - Eigen::Vector3d(0, 1, 0)).norm(), 0, 1e-12);
  EXPECT_THROW(attached.Evaluate(0.0, {0, 0, 0}), Error);
  a.Get<FlashlightParams>().attach = "robot/arm";
  EXPECT_THROW(EffectsEngine({a}, 1, scene), ConfigError);
}

TEST(EffectsEngineTest, SunSetsDirectionAndDimsTheSkyAtNight) {
  EffectConfig e;
  e.name = "sun";
  e.params = SunParams{};
  e.Get<SunParams>().latitude_deg = 48.14;
  e.Get<SunParams>().longitude_deg = 11.58;
  e.Get<SunParams>().year = 2024;
  e.Get<SunParams>().month = 6;
  e.Get<SunParams>().day = 21;
  e.Get<SunParams>().time_utc_h = 11.0;  // about local solar noon in Munich
  e.Get<SunParams>().time_scale = 3600;  // one hour per sim second
  EffectsEngine engine({e}, 1, SceneDescription{});
  auto noon = engine.Evaluate(0.0, {0, 0, 0});
  ASSERT_TRUE(noon->sun_direction_W);
  // noon elevation = 90 - lat + declination (23.44) ~ 65.3 deg, sun due south
  EXPECT_NEAR(std::asin(noon->sun_direction_W->z()) * 180 / M_PI, 65.3, 0.5);
  EXPECT_LT(noon->sun_direction_W->y(), 0);
  EXPECT_EQ(noon->sky_luminance_scale, 1.0f);
  auto night = engine.Evaluate(12.0, {0, 0, 0});  // 23:00 UTC
  EXPECT_LT(night->sun_direction_W->z(), 0);
  EXPECT_LT(night->sky_luminance_scale, 0.01f);
}

TEST(EffectsEngineTest, SunMovesTheSceneSunLight) {
  SceneDescription scene;
  Light lamp;
  lamp.name = "lamp";
  lamp.type = Light::Type::kPoint;
  Light sun;
  sun.name = "sun";
  sun.type = Light::Type::kDirectional;
  sun.direction_B = Eigen::Vector3d(0, 0, -1);
  sun.intensity = 100000;
  scene.lights = {lamp, sun};
  EffectConfig e;
  e.name = "day";
  e.params = SunParams{};
  e.Get<SunParams>().time_utc_h = 11.0;
  e.Get<SunParams>().time_scale = 3600;
  EffectsEngine engine({e}, 1, scene);
  auto noon = engine.Evaluate(0.0, {0, 0, 0});
  ASSERT_EQ(noon->light_intensity_scale.size(), 2u);
  EXPECT_EQ(noon->light_intensity_scale[0], 1.0f);  // the lamp is left alone
  EXPECT_EQ(noon->light_intensity_scale[1], 0.0f);  // the configured sun is replaced
  ASSERT_EQ(noon->extra_lights.size(), 1u);
  const Light& moved = noon->extra_lights[0];
  EXPECT_EQ(moved.type, Light::Type::kDirectional);
  EXPECT_NEAR((moved.direction_B + *noon->sun_direction_W).norm(), 0, 1e-12);
  // at ~65 deg elevation the beam is a few percent weaker than at the zenith
  const double elevation = std::asin(noon->sun_direction_W->z()) * 180 / M_PI;
  EXPECT_NEAR(moved.intensity, 100000 * DirectSunAttenuation(elevation), 1.0);
  EXPECT_GT(moved.intensity, 90000);
  EXPECT_LT(moved.intensity, 100000);
  // at night the sun is gone
  auto night = engine.Evaluate(12.0, {0, 0, 0});
  EXPECT_EQ(night->light_intensity_scale[1], 0.0f);
  EXPECT_TRUE(night->extra_lights.empty());
}

TEST(EffectsEngineTest, DirectSunAttenuationFollowsAirMass) {
  EXPECT_NEAR(DirectSunAttenuation(90), 1.0, 1e-3);  // Kasten-Young AM(90 deg) = 0.9997
  EXPECT_EQ(DirectSunAttenuation(0), 0.0);
  EXPECT_EQ(DirectSunAttenuation(-5), 0.0);
  // AM(30 deg) is just under the flat-earth 1 / sin(30 deg) = 2 (1.9943 by the formula)
  EXPECT_NEAR(DirectSunAttenuation(30), std::pow(0.7, std::pow(1.9942, 0.678)) / 0.7, 1e-3);
  EXPECT_NEAR(DirectSunAttenuation(0.01), 0.021, 0.001);  // AM ~ 38 at the horizon
}

TEST(EffectsEngineTest, WetnessFollowsRain) {
  EffectConfig rain;
  rain.name = "rain";
  rain.params = RainParams{};
  rain.start_sec = 10;
  rain.stop_sec = 70;
  rain.Get<RainParams>().box_half_extents_m = {1, 1, 1};
  EffectConfig wet;
  wet.name = "wet";
  wet.params = WetnessParams{};
  wet.Get<WetnessParams>().wetting_time_sec = 20;
  wet.Get<WetnessParams>().drying_time_sec = 100;
  EffectsEngine engine({rain, wet}, 1, SceneDescription{});
  EXPECT_EQ(engine.Evaluate(5, {0, 0, 0})->surface_wetness, 0.0f);
  auto during = engine.Evaluate(30, {0, 0, 0});
  EXPECT_NEAR(during->surface_wetness, 1 - std::exp(-1.0), 1e-6);
  EXPECT_EQ(during->particles.size(), 1u);
  const double at_stop = 1 - std::exp(-3.0);
  auto after = engine.Evaluate(170, {0, 0, 0});
  EXPECT_NEAR(after->surface_wetness, at_stop * std::exp(-1.0), 1e-6);
  EXPECT_TRUE(after->particles.empty());
}

TEST(EffectConfigTest, ErrorsNameEffectKeyAndRange) {
  EffectConfig e = Fog();
  e.Get<FogParams>().extinction.mor_m = 0.0;
  try {
    e.ValidateOrThrow("effects[4]");
    FAIL();
  } catch (const ConfigError& err) {
    EXPECT_EQ(err.key(), "effects[4].mor_m");
    EXPECT_NE(std::string(err.what()).find("effect 'fog' (fog)"), std::string::npos);
    EXPECT_NE(std::string(err.what()).find("expected [0.001, 1e+05]"), std::string::npos)
        << err.what();
  }
  EffectConfig r;
  r.name = "r";
  r.params = RainParams{};
  r.Get<RainParams>().rate_mm_h = -1;
  EXPECT_EQ(r.Validate()->key, "rate_mm_h");
  r.Get<RainParams>().rate_mm_h = 5;
  r.region = BoxRegion{{0, 0, 0}, {1, -1, 1}};
  EXPECT_EQ(r.Validate()->key, "region.min");
  r.region.reset();
  EXPECT_FALSE(r.Validate());
  EffectConfig s = Smoke(SmokeParams::Mode::kPlume);
  s.Get<SmokeParams>().fluid.emitters[0].position_W = {5, 0, 0};
  EXPECT_EQ(s.Validate()->key, "emitters[0].position");
  // duplicate names and dangling references
  EXPECT_THROW(ValidateEffectsOrThrow({Fog(), Fog()}), ConfigError);
  EffectConfig w;
  w.name = "w";
  w.params = WetnessParams{};
  try {
    ValidateEffectsOrThrow({Fog(), w}, "world.yaml", [](const std::string&) { return 12; });
    FAIL();
  } catch (const ConfigError& err) {
    EXPECT_EQ(err.key(), "effects[1].rain");
    EXPECT_EQ(err.line(), 12);
    EXPECT_EQ(err.file(), "world.yaml");
  }
}

TEST(EffectsEngineTest, SparksRiseFromTheirSourceAndFallBack) {
  EffectConfig e;
  e.name = "sparks";
  e.params = SparksParams{};
  e.Get<SparksParams>().position_W = {1, 1, 0.5};
  e.Get<SparksParams>().rate_per_s = 100;
  e.Get<SparksParams>().lifetime_sec = 1;
  EffectsEngine engine({e}, 1, SceneDescription{});
  auto f = engine.Evaluate(3.0, {0, 0, 0});
  ASSERT_EQ(f->particles.size(), 1u);
  const ParticleSet& s = f->particles[0];
  EXPECT_EQ(s.kind, ParticleKind::kSpark);
  EXPECT_NEAR(static_cast<double>(s.position_W.size()), 100.0, 1.0);
  EXPECT_GT(s.emission.x(), s.emission.z());
  for (size_t i = 0; i < s.position_W.size(); ++i) {
    ASSERT_LE(s.radius_m[i], 0.004f);
    ASSERT_LT((s.position_W[i] - Eigen::Vector3f(1, 1, 0.5)).norm(), 2.6f);
  }
}

}  // namespace
}  // namespace penumbra
