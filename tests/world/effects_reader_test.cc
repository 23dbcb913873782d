// the world file's `effects:` list: every type parses, bad values name file, line, key, range.
#include "penumbra/world/effects_reader.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/temp_dir.h"
#include "penumbra/core/error.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

const std::string kEffects = R"(duration_sec: 5
effects:
  - {name: haze, type: fog, mor_m: 80, height_falloff_per_m: 0.3, base_height_m: 1}
  - name: dusty
    type: dust
    sigma_t_per_m: 0.02
    color: [0.8, 0.6, 0.4]
    region: {min: [-5, -5, 0], max: [5, 5, 3]}
  - name: plume
    type: smoke
    mode: plume
    region: {min: [-1, -1, 0], max: [1, 1, 2]}
    resolution: 32
    emitters: [{position: [0, 0, 0.2], radius_m: 0.1, rate: 0.3}]
  - {name: cloud, type: vdb_smoke, file: assets/cloud.vdb}
  - name: campfire
    type: fire
    region: {min: [2, 2, 0], max: [3, 3, 1.5]}
    emitters: [{position: [2.5, 2.5, 0.1], temperature_k: 1400}]
  - {name: storm, type: rain, rate_mm_h: 20, wind_m_s: [3, 0, 0], start_sec: 2, fade_in_sec: 1}
  - {name: flurry, type: snow, rate_mm_h: 1, flake_diameter_mm: 6, sheltered: false}
  - {name: embers, type: sparks, fire: campfire, rate_per_s: 30}
  - {name: bad_bulb, type: light_event, light: ceiling, mode: strobe, frequency_hz: 4}
  - name: torch
    type: flashlight
    waypoints:
      - {t_sec: 0, position: [0, 0, 1.5], direction: [1, 0, 0]}
      - {t_sec: 4, position: [4, 0, 1.5], direction: [0, 1, 0]}
  - {name: clock, type: sun, latitude_deg: 52.5, longitude_deg: 13.4, month: 12, day: 1, time_utc_h: 15}
  - {name: puddles, type: wetness, rain: storm, drying_time_sec: 300}
)";

std::string ErrorOf(const std::string& yaml, ConfigError* out = nullptr) {
  try {
    ParseWorld(yaml, "w.yaml");
  } catch (const ConfigError& e) {
    if (out) *out = e;
    return e.what();
  }
  return "";
}

TEST(WorldEffects, ParsesEveryType) {
  // the .vdb file must exist at load (its grid is read when the effects are built)
  const testing::TempDir dir;
  const std::string vdb = dir.Write("assets/cloud.vdb", "");
  const WorldConfig w = ParseWorld(kEffects, (dir.path() / "w.yaml").string());
  ASSERT_EQ(w.effects.size(), 12u);
  const auto& e = w.effects;
  EXPECT_TRUE(e[0].Is<FogParams>());
  EXPECT_NEAR(e[0].Get<FogParams>().extinction.SigmaT(), 2.9957 / 80, 1e-5);
  EXPECT_EQ(e[0].Get<FogParams>().height_falloff_per_m, 0.3);
  EXPECT_EQ(e[1].Get<DustParams>().color, Eigen::Vector3d(0.8, 0.6, 0.4));
  ASSERT_TRUE(e[1].region);
  EXPECT_EQ(e[1].region->max_W, Eigen::Vector3d(5, 5, 3));
  EXPECT_EQ(e[2].Get<SmokeParams>().mode, SmokeParams::Mode::kPlume);
  EXPECT_EQ(e[2].Get<SmokeParams>().fluid.resolution, 32);
  ASSERT_EQ(e[2].Get<SmokeParams>().fluid.emitters.size(), 1u);
  EXPECT_EQ(e[2].Get<SmokeParams>().fluid.emitters[0].rate, 0.3);
  EXPECT_EQ(e[3].Get<VdbSmokeParams>().file, vdb);  // relative to the world file
  EXPECT_EQ(e[4].Get<FireParams>().fluid.emitters[0].temperature_k, 1400);
  EXPECT_EQ(e[5].Get<RainParams>().rate_mm_h, 20);
  EXPECT_TRUE(e[5].Get<RainParams>().sheltered);  // the default
  EXPECT_EQ(e[5].start_sec, 2);
  EXPECT_TRUE(std::isinf(e[5].stop_sec));
  EXPECT_EQ(e[6].Get<SnowParams>().flake_diameter_mm, 6);
  EXPECT_FALSE(e[6].Get<SnowParams>().sheltered);
  EXPECT_EQ(e[7].Get<SparksParams>().fire, "campfire");
  EXPECT_EQ(e[8].Get<LightEventParams>().mode, LightEventParams::Mode::kStrobe);
  ASSERT_EQ(e[9].Get<FlashlightParams>().waypoints.size(), 2u);
  EXPECT_EQ(e[9].Get<FlashlightParams>().waypoints[1].position_W, Eigen::Vector3d(4, 0, 1.5));
  EXPECT_EQ(e[10].Get<SunParams>().month, 12);
  EXPECT_EQ(e[11].Get<WetnessParams>().rain, "storm");
}

struct BadCase {
  const char* yaml_entry;  // one effects entry on line 3 of the document
  const char* key;
  const char* expect;  // part of the message (the valid range)
};

class WorldEffectsBad : public ::testing::TestWithParam<BadCase> {};

TEST_P(WorldEffectsBad, NamesFileLineKeyAndRange) {
  const BadCase c = GetParam();
  const std::string yaml =
      std::string("duration_sec: 5\neffects:\n  - {name: a, type: fog, mor_m: 10}\n") + "  - " +
      c.yaml_entry + "\n";
  ConfigError err("", 0, "", "");
  const std::string what = ErrorOf(yaml, &err);
  ASSERT_FALSE(what.empty()) << c.yaml_entry;
  EXPECT_EQ(err.file(), "w.yaml");
  EXPECT_EQ(err.line(), 4) << what;
  EXPECT_EQ(err.key(), c.key) << what;
  EXPECT_NE(what.find(c.expect), std::string::npos) << what;
}

INSTANTIATE_TEST_SUITE_P(
    Cases, WorldEffectsBad,
    ::testing::Values(
        BadCase{"{name: s, type: smoke, mode: noise, density_scale_per_m: -1, region: {min: [0, 0, "
                "0], max: [1, 1, 1]}}",
                "effects[1].density_scale_per_m", "expected (0, 1000]"},
        BadCase{"{name: f, type: fog, mor_m: 0}", "effects[1].mor_m", "expected [0.001, 1e+05]"},
        BadCase{"{name: f, type: fog, sigma_t_per_m: -0.5}", "effects[1].sigma_t_per_m",
                "expected (0, 1000]"},
        BadCase{"{name: t, type: tornado}", "effects[1].type",
                "expected one of: fog, dust, smoke, vdb_smoke, fire, rain"},
        BadCase{"{name: r, type: rain, region: {min: [0, 0, 5], max: [1, 1, 1]}}",
                "effects[1].region.min", "expected min < max on every axis"},
        BadCase{"{name: r, type: rain, rate_mm_h: 0}", "effects[1].rate_mm_h", "expected (0, 500]"},
        BadCase{"{name: r, type: rain, hail: true}", "effects[1].hail", "unknown key 'hail'"},
        BadCase{"{name: r, type: rain, sheltered: 3}", "effects[1].sheltered", "expected"},
        BadCase{"{name: a, type: rain}", "effects[1].name", "expected unique effect names"},
        BadCase{"{name: w, type: wetness, rain: nope}", "effects[1].rain",
                "expected the name of a rain effect"},
        BadCase{"{name: l, type: light_event, light: x, mode: strobe, duty_cycle: 1.5}",
                "effects[1].duty_cycle", "expected (0, 1)"},
        BadCase{"{name: s, type: sun, month: 2, day: 30}", "effects[1].day", "expected [1, 29]"}));

TEST(WorldEffects, ErrorLineIsThatOfTheKeyInBlockStyle) {
  ConfigError err("", 0, "", "");
  const std::string what = ErrorOf(R"(effects:
  - name: drizzle
    type: rain
    rate_mm_h: 2
    min_diameter_mm: 3
    max_diameter_mm: 2
)",
                                   &err);
  EXPECT_EQ(err.key(), "effects[0].max_diameter_mm") << what;
  EXPECT_EQ(err.line(), 6) << what;
  EXPECT_NE(what.find("effect 'drizzle' (rain)"), std::string::npos) << what;
  EXPECT_NE(what.find("expected > min_diameter_mm (3) and <= 6"), std::string::npos) << what;
}

TEST(WorldEffects, MissingNameOrTypeIsAnError) {
  EXPECT_NE(ErrorOf("effects:\n  - {type: fog, mor_m: 3}\n").find("effects[0].name"),
            std::string::npos);
  EXPECT_NE(ErrorOf("effects:\n  - {name: x}\n").find("effects[0].type"), std::string::npos);
  EXPECT_NE(ErrorOf("effects: {a: 1}\n").find("expected a list"), std::string::npos);
}

TEST(WorldEffects, UnknownTypeListsEveryRegisteredType) {
  ConfigError err("", 0, "", "");
  const std::string what = ErrorOf("effects:\n  - {name: x, type: hail}\n", &err);
  std::string names;
  for (const std::string& n : EffectTypeNames()) names += (names.empty() ? "" : ", ") + n;
  EXPECT_EQ(err.key(), "effects[0].type") << what;
  EXPECT_EQ(err.line(), 2) << what;
  EXPECT_NE(what.find("unknown value 'hail'; expected one of: " + names), std::string::npos)
      << what;
  EXPECT_NE(what.find("fog, dust, smoke, vdb_smoke, fire, rain, snow, sparks, light_event, "
                      "flashlight, sun, wetness"),
            std::string::npos)
      << what;
}

TEST(WorldEffects, EachTypeAcceptsOnlyItsOwnKeys) {
  // a key of another type is unknown: "mor_m" belongs to fog and dust, not rain
  ConfigError err("", 0, "", "");
  const std::string what = ErrorOf("effects:\n  - {name: r, type: rain, mor_m: 3}\n", &err);
  EXPECT_EQ(err.key(), "effects[0].mor_m") << what;
  EXPECT_NE(what.find("unknown key 'mor_m'"), std::string::npos) << what;
  // the message lists the common keys, then the type's own keys (its registry entry)
  std::string keys = "name, type, start_sec, stop_sec, fade_in_sec, fade_out_sec, region";
  for (std::string_view k : FindEffectType("rain")->keys) keys += ", " + std::string(k);
  EXPECT_NE(what.find(keys), std::string::npos) << what;
}

}  // namespace
}  // namespace penumbra
