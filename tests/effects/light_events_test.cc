// light events follow their definitions; the engine applies them to the named lights.
#include "penumbra/effects/light_events.h"

#include <gtest/gtest.h>

#include <cmath>

#include "penumbra/core/error.h"
#include "penumbra/effects/effects_engine.h"

namespace penumbra {
namespace {

EffectConfig Event(LightEventParams::Mode mode) {
  EffectConfig e;
  e.name = "ev";
  e.params = LightEventParams{};
  e.Get<LightEventParams>().light = "lamp";
  e.Get<LightEventParams>().mode = mode;
  return e;
}

TEST(LightEventTest, StrobeFollowsFrequencyAndDutyCycle) {
  EffectConfig e = Event(LightEventParams::Mode::kStrobe);
  e.start_sec = 1.0;
  e.stop_sec = 10.0;
  e.Get<LightEventParams>().frequency_hz = 2.0;
  e.Get<LightEventParams>().duty_cycle = 0.25;
  e.Get<LightEventParams>().min_scale = 0.1;
  EXPECT_DOUBLE_EQ(LightEventScale(e, 0.5, 1), 1.0);   // before start
  EXPECT_DOUBLE_EQ(LightEventScale(e, 1.05, 1), 1.0);  // phase 0.1 < 0.25: on
  EXPECT_DOUBLE_EQ(LightEventScale(e, 1.2, 1), 0.1);   // phase 0.4: off
  EXPECT_DOUBLE_EQ(LightEventScale(e, 1.55, 1), 1.0);  // next period, phase 0.1
  EXPECT_DOUBLE_EQ(LightEventScale(e, 1.9, 1), 0.1);
  EXPECT_DOUBLE_EQ(LightEventScale(e, 11.0, 1), 1.0);  // after stop
  // the on-fraction over many periods is the duty cycle
  int on = 0;
  const int n = 10000;
  for (int i = 0; i < n; ++i) on += LightEventScale(e, 1.0 + 8.0 * (i + 0.5) / n, 1) == 1.0;
  EXPECT_NEAR(static_cast<double>(on) / n, 0.25, 0.005);
}

TEST(LightEventTest, FlickerStaysWithinDepthAndIsSmooth) {
  EffectConfig e = Event(LightEventParams::Mode::kFlicker);
  e.Get<LightEventParams>().frequency_hz = 10;
  e.Get<LightEventParams>().depth = 0.4;
  double lo = 1, hi = 0, prev = LightEventScale(e, 0, 3), max_step = 0;
  for (int i = 1; i <= 20000; ++i) {
    const double s = LightEventScale(e, i * 1e-4, 3);
    lo = std::min(lo, s);
    hi = std::max(hi, s);
    max_step = std::max(max_step, std::abs(s - prev));
    prev = s;
  }
  EXPECT_GE(lo, 0.6 - 1e-12);
  EXPECT_LE(hi, 1.0);
  EXPECT_GT(hi - lo, 0.2);  // it does flicker
  // quintic fade: slope <= 1.875 x depth x f per second -> <= 7.5e-4 per 0.1 ms
  EXPECT_LE(max_step, 1.875 * 0.4 * 10 * 1e-4 + 1e-9);
}

TEST(LightEventTest, FailingDropsOutWithItsProbability) {
  EffectConfig e = Event(LightEventParams::Mode::kFailing);
  e.Get<LightEventParams>().frequency_hz = 5;
  e.Get<LightEventParams>().failure_probability = 0.3;
  e.Get<LightEventParams>().min_scale = 0.0;
  int off = 0;
  const int slots = 4000;
  for (int i = 0; i < slots; ++i) off += LightEventScale(e, (i + 0.5) / 5.0, 9) == 0.0;
  EXPECT_NEAR(static_cast<double>(off) / slots, 0.3, 0.03);
}

TEST(LightEventTest, BlackoutThenLinearRecovery) {
  EffectConfig e = Event(LightEventParams::Mode::kBlackout);
  e.start_sec = 2;
  e.stop_sec = 5;
  e.Get<LightEventParams>().recovery_sec = 2;
  e.Get<LightEventParams>().min_scale = 0;
  EXPECT_DOUBLE_EQ(LightEventScale(e, 1.0, 1), 1.0);
  EXPECT_DOUBLE_EQ(LightEventScale(e, 2.0, 1), 0.0);
  EXPECT_DOUBLE_EQ(LightEventScale(e, 4.9, 1), 0.0);
  EXPECT_DOUBLE_EQ(LightEventScale(e, 6.0, 1), 0.5);
  EXPECT_DOUBLE_EQ(LightEventScale(e, 6.5, 1), 0.75);
  EXPECT_DOUBLE_EQ(LightEventScale(e, 7.0, 1), 1.0);
  EXPECT_DOUBLE_EQ(LightEventScale(e, 100.0, 1), 1.0);
}

TEST(LightEventTest, EngineScalesOnlyTheNamedLight) {
  SceneDescription scene;
  scene.lights.resize(3);
  scene.lights[0].name = "sun";
  scene.lights[1].name = "lamp";
  scene.lights[2].name = "lamp2";
  EffectConfig e = Event(LightEventParams::Mode::kBlackout);
  e.start_sec = 1;
  e.stop_sec = 2;
  EffectsEngine engine({e}, 7, scene);
  auto f = engine.Evaluate(1.5, {0, 0, 0});
  ASSERT_EQ(f->light_intensity_scale.size(), 3u);
  EXPECT_EQ(f->light_intensity_scale[0], 1.0f);
  EXPECT_EQ(f->light_intensity_scale[1], 0.0f);
  EXPECT_EQ(f->light_intensity_scale[2], 1.0f);
  EXPECT_FALSE(f->empty());

  e.Get<LightEventParams>().light = "nope";
  try {
    EffectsEngine bad({e}, 7, scene);
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& err) {
    EXPECT_EQ(err.key(), "effects[0].light");
    EXPECT_NE(std::string(err.what()).find("lamp2"), std::string::npos) << err.what();
  }
}

}  // namespace
}  // namespace penumbra
