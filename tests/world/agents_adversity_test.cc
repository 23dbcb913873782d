// world-file `agents:` and `adversity:` keys, and the bundled adversity presets.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "common/temp_dir.h"
#include "penumbra/core/error.h"
#include "penumbra/world/adversity_preset.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

const std::string kAgents = R"(
duration_sec: 1
agents:
  - name: walker
    waypoints: [[0, 0], [3, 0], [3, 2]]
    speed_m_s: 1.1
    pause_sec: 2
    route: pingpong
  - name: lift
    type: forklift
    waypoints: [[-1, -1], [-4, -1]]
    start_delay_sec: 3
)";

std::string ErrorOf(const std::string& yaml) {
  try {
    ParseWorld(yaml, "w.yaml");
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(WorldAgents, ParsesEveryKey) {
  const WorldConfig w = ParseWorld(kAgents, "w.yaml");
  ASSERT_EQ(w.agents.size(), 2u);
  EXPECT_EQ(w.agents[0].name, "walker");
  EXPECT_EQ(w.agents[0].kind, AgentKind::kPerson);
  EXPECT_EQ(w.agents[0].waypoints.size(), 3u);
  EXPECT_EQ(w.agents[0].waypoints[2], Eigen::Vector2d(3, 2));
  EXPECT_EQ(w.agents[0].speed_m_s, 1.1);
  EXPECT_EQ(w.agents[0].pause_sec, 2);
  EXPECT_EQ(w.agents[0].route, AgentRoute::kPingPong);
  EXPECT_EQ(w.agents[0].line, 4);
  EXPECT_EQ(w.agents[1].kind, AgentKind::kForklift);
  EXPECT_EQ(w.agents[1].start_delay_sec, 3);
  EXPECT_EQ(w.agents[1].route, AgentRoute::kLoop);
  // agents never push robots unless asked to (`contact: true`)
  EXPECT_FALSE(w.agents[0].robot_contact);
  const WorldConfig pushing =
      ParseWorld("agents:\n  - {name: a, waypoints: [[0, 0], [1, 0]], contact: true}\n", "w.yaml");
  EXPECT_TRUE(pushing.agents[0].robot_contact);
  EXPECT_NE(ErrorOf("agents:\n  - {name: a, waypoints: [[0, 0], [1, 0]], contact: 3}\n")
                .find("agents[0].contact"),
            std::string::npos);
}

TEST(AdversityPresets, NpcsContactKeyReadsAndRoundTrips) {
  const auto dir = std::filesystem::path(penumbra::testing::ProcessTempDir());
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "push.yaml") << "presets:\n  push:\n    npcs: {people: 2, contact: true}\n";
  const AdversityPreset p = LoadAdversityPreset((dir / "push.yaml").string());
  EXPECT_TRUE(p.npc_contact);
  EXPECT_FALSE(LoadAdversityPreset("major").npc_contact);  // bundled presets never push
  EXPECT_FALSE(LoadAdversityPreset("minor").npc_contact);
  const std::vector<AdversityPreset> back =
      ParseAdversityPresets(AdversityPresetFileText(p), "again.yaml");
  ASSERT_EQ(back.size(), 1u);
  EXPECT_TRUE(back[0].npc_contact);
  std::ofstream(dir / "bad.yaml") << "presets:\n  bad:\n    npcs: {contact: maybe}\n";
  try {
    LoadAdversityPreset((dir / "bad.yaml").string());
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("npcs.contact"), std::string::npos) << e.what();
  }
}

TEST(WorldAgents, BadInputNamesFileLineKeyAndRange) {
  std::string e = ErrorOf("agents:\n  - name: a\n    waypoints: [[0, 0]]\n");
  EXPECT_EQ(e,
            "w.yaml:3: agents[0].waypoints: agent 'a' has 1 waypoint(s); expected a list of at "
            "least 2 [x, y] points");
  e = ErrorOf("agents:\n  - name: a\n    waypoints: [[0, 0], [1, 0]]\n    speed_m_s: -0.5\n");
  EXPECT_EQ(e, "w.yaml:4: agents[0].speed_m_s: got -0.5; expected (0, 20] m/s");
  e = ErrorOf("agents:\n  - name: a\n    waypoints: [[0, 0], [1, 0, 2]]\n");
  EXPECT_NE(e.find("w.yaml:3: agents[0].waypoints[1]: expected a floor point [x, y]"),
            std::string::npos)
      << e;
  e = ErrorOf("agents:\n  - name: a\n    type: robot\n    waypoints: [[0, 0], [1, 0]]\n");
  EXPECT_NE(
      e.find("agents[0].type: unknown value 'robot'; expected one of: person, forklift, cart"),
      std::string::npos)
      << e;
  e = ErrorOf(
      "agents:\n  - name: a\n    waypoints: [[0, 0], [1, 0]]\n  - name: a\n    waypoints: [[0, 0], "
      "[1, 0]]\n");
  EXPECT_NE(e.find("w.yaml:4: agents[1].name: duplicate agent name 'a'"), std::string::npos) << e;
  e = ErrorOf("agents:\n  - name: a\n    waypoints: [[0, 0], [1, 0]]\n    speed: 2\n");
  EXPECT_NE(e.find("agents[0].speed: unknown key 'speed'"), std::string::npos) << e;
}

TEST(AdversityPresets, BundledNoneMinorMajorWithIncreasingSeverity) {
  const std::vector<std::string> names = BundledAdversityPresetNames();
  ASSERT_EQ(names, (std::vector<std::string>{"none", "minor", "major"}));
  const AdversityPreset none = LoadAdversityPreset("none");
  const AdversityPreset minor = LoadAdversityPreset("minor");
  const AdversityPreset major = LoadAdversityPreset("major");
  EXPECT_TRUE(none.empty());
  EXPECT_FALSE(minor.empty());
  ASSERT_TRUE(minor.fog_mor_m && major.fog_mor_m);
  EXPECT_LT(*major.fog_mor_m, *minor.fog_mor_m);
  ASSERT_TRUE(minor.smoke_sigma_t_per_m && major.smoke_sigma_t_per_m);
  EXPECT_GT(*major.smoke_sigma_t_per_m, *minor.smoke_sigma_t_per_m);
  ASSERT_TRUE(minor.rain_rate_mm_h && major.rain_rate_mm_h);
  EXPECT_GT(*major.rain_rate_mm_h, *minor.rain_rate_mm_h);
  EXPECT_LT(major.light_scale, minor.light_scale);
  EXPECT_GT(major.npc_people + major.npc_vehicles, minor.npc_people + minor.npc_vehicles);
}

TEST(AdversityPresets, EveryBundledPresetStatesWhatItDoesToEachSensor) {
  for (const std::string& name : {"minor", "major"}) {
    const AdversityPreset p = LoadAdversityPreset(name);
    std::vector<std::string> sensors;
    for (const auto& [sensor, text] : p.sensor_effects) {
      sensors.push_back(sensor);
      EXPECT_GT(text.size(), 20u) << name << " " << sensor;
    }
    EXPECT_EQ(sensors, AdversitySensorNames()) << name;
    // a preset written back (penumbra benchmark's per-episode files) keeps them
    const std::vector<AdversityPreset> back =
        ParseAdversityPresets(AdversityPresetFileText(p), "again.yaml");
    ASSERT_EQ(back.size(), 1u);
    EXPECT_EQ(back[0].sensor_effects, p.sensor_effects) << name;
  }
  try {
    ParseAdversityPresets("presets:\n  p:\n    sensors: {sonar: loud}\n", "p.yaml");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("sensors.sonar: unknown key"), std::string::npos)
        << e.what();
  }
}

TEST(AdversityPresets, TheExampleUserFileLoads) {
  const std::string file = std::string(PENUMBRA_SOURCE_DIR) + "/worlds/adversity/night_shift.yaml";
  const AdversityPreset p = LoadAdversityPreset(file + "#night_shift");
  EXPECT_EQ(p.npc_vehicles, 2);
  EXPECT_EQ(*p.dust_mor_m, 20);
  EXPECT_EQ(*LoadAdversityPreset(file + "#blizzard").snow_rate_mm_h, 8);
}

TEST(AdversityPresets, WorldKeyAndErrors) {
  EXPECT_EQ(ParseWorld("adversity: major\n", "w.yaml").adversity, "major");
  EXPECT_EQ(ErrorOf("duration_sec: 2\nadversity: extreme\n"),
            "w.yaml:2: adversity: unknown preset 'extreme'; expected one of: none, minor, major, "
            "or a preset file (FILE.yaml or FILE.yaml#NAME)");
  // a user file, relative to the world file
  const auto dir = std::filesystem::path(penumbra::testing::ProcessTempDir());
  std::filesystem::create_directories(dir);
  {
    std::ofstream f(dir / "mine.yaml");
    f << "presets:\n  foggy:\n    fog: {mor_m: 5}\n  smoky:\n    smoke: {sigma_t_per_m: 3}\n";
  }
  const std::string world = (dir / "w.yaml").string();
  const WorldConfig w = ParseWorld("adversity: mine.yaml#smoky\n", world);
  EXPECT_EQ(w.adversity, (dir / "mine.yaml").string() + "#smoky");
  const AdversityPreset p = LoadAdversityPreset(w.adversity);
  EXPECT_EQ(p.name, "smoky");
  EXPECT_EQ(*p.smoke_sigma_t_per_m, 3);
  try {
    ParseWorld("adversity: mine.yaml\n", world);
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find(
                  "holds 2 presets; expected FILE.yaml#NAME with NAME one of: foggy, smoky"),
              std::string::npos)
        << e.what();
  }
  {
    std::ofstream f(dir / "bad.yaml");
    f << "presets:\n  wet:\n    rain: {rate_mm_h: 900}\n";
  }
  try {
    ParseWorld("adversity: bad.yaml\n", world);
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.line(), 3);
    EXPECT_EQ(e.key(), "presets.wet.rain.rate_mm_h");
    EXPECT_NE(std::string(e.what()).find("got 900; expected (0, 500] mm/h"), std::string::npos);
  }
}

}  // namespace
}  // namespace penumbra
