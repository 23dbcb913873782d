// finite but absurd world-file values that used to be accepted (a lens distortion k1 of 1e6,
// an agent far off in 1e300 m, a flashlight of 1e308 cd, sparks of 1e308 cd/m^2 that ended
// the run with exit 1 and no line, effect times, rates and accelerations that overflow the
// renderer's floats) are refused at load with the file, the line, the key and the range
// (scene/scene_limits.h, docs/world-file.md "Input limits").

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <utility>

#include "common/temp_dir.h"
#include "penumbra/core/error.h"
#include "penumbra/scene/scene_limits.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

struct BadValue {
  std::string yaml;  // the whole world file
  int line;          // the line of the offending key
  std::string key;
  std::string text;  // part of the message (the range)
};

std::ostream& operator<<(std::ostream& os, const BadValue& b) { return os << b.key; }

class WorldValuesTest : public ::testing::TestWithParam<BadValue> {
 protected:
  penumbra::testing::TempDir dir_;
};

TEST_P(WorldValuesTest, IsRefusedWithFileLineKeyAndRange) {
  const BadValue& b = GetParam();
  const std::string world = (dir_.path() / "world.yaml").string();
  try {
    ParseWorld(b.yaml, world);
    ADD_FAILURE() << "no ConfigError for:\n" << b.yaml;
  } catch (const ConfigError& e) {
    const std::string what = e.what();
    EXPECT_EQ(e.file(), world) << what;
    EXPECT_EQ(e.line(), b.line) << what;
    EXPECT_EQ(e.key(), b.key) << what;
    EXPECT_NE(what.find(b.text), std::string::npos) << "expected '" << b.text << "' in: " << what;
  }
}

const std::string kBadCamBase = "cameras:\n  - name: c\n    fovy_deg: 60\n";
const std::string kBadTorchBase =
    "effects:\n  - name: torch\n    type: flashlight\n"
    "    waypoints: [{t_sec: 0, position: [0, 0, 1], direction: [1, 0, 0]}]\n";
const std::string kBadPlumeBase =
    "effects:\n  - name: plume\n    type: smoke\n    mode: plume\n"
    "    region: {min: [-1, -1, 0], max: [1, 1, 2]}\n";
const std::string kBadAgentBase = "agents:\n  - name: bob\n    waypoints: [[0, 0], [1, 0]]\n";
const std::string kBadSensorBase = "sensors:\n  - name: s\n    type: imu\n    body: world\n";

INSTANTIATE_TEST_SUITE_P(
    Bounds, WorldValuesTest,
    ::testing::Values(
        // lens distortion: a positive k1 of 1e6 is one-to-one, so the fold check let it pass
        BadValue{kBadCamBase + "    distortion: {k1: 1e6}\n", 4, "cameras[0].distortion.k1",
                 "got 1e+06; expected [-100, 100]"},
        BadValue{kBadCamBase + "    distortion:\n      k2: 0.1\n      k3: -1e300\n", 6,
                 "cameras[0].distortion.k3", "expected [-100, 100]"},
        BadValue{kBadCamBase + "    distortion: {p1: 2}\n", 4, "cameras[0].distortion.p1",
                 "got 2; expected [-1, 1]"},
        // lights: a direction whose square overflows became the zero vector
        BadValue{"lights:\n  - name: sun\n    type: directional\n    illuminance_lux: 1000\n"
                 "    direction: [1e300, 0, -1]\n",
                 5, "lights[0].direction", "expected each of the 3 numbers in [-1e+05, 1e+05]"},
        // flashlight
        BadValue{kBadTorchBase + "    intensity_cd: 1e308\n", 5, "effects[0].intensity_cd",
                 "1e+308 is out of range; expected (0, 1e+09]"},
        BadValue{kBadTorchBase + "    radius_m: 1e300\n", 5, "effects[0].radius_m",
                 "expected [0, 1e+05]"},
        BadValue{"effects:\n  - name: torch\n    type: flashlight\n    waypoints:\n"
                 "      - {t_sec: 1e300, position: [0, 0, 1], direction: [1, 0, 0]}\n",
                 5, "effects[0].waypoints[0].t_sec", "expected [0, 1e+06]"},
        BadValue{"effects:\n  - name: torch\n    type: flashlight\n    waypoints:\n"
                 "      - {t_sec: 0, position: [1e300, 0, 1], direction: [1, 0, 0]}\n",
                 5, "effects[0].waypoints[0].position", "each [-1e+05, 1e+05]"},
        BadValue{"effects:\n  - name: torch\n    type: flashlight\n    attach: r/b\n"
                 "    direction: [1e200, 1e200, 0]\n",
                 5, "effects[0].direction", "each [-1e+05, 1e+05]"},
        // sparks of 1e308 cd/m^2 ended the run with exit 1 and no line
        BadValue{"effects:\n  - name: embers\n    type: sparks\n    luminance_cd_m2: 1e308\n", 4,
                 "effects[0].luminance_cd_m2", "expected [0, 1e+10]"},
        BadValue{"effects:\n  - name: embers\n    type: sparks\n    position: [0, -1e300, 0]\n", 4,
                 "effects[0].position", "each [-1e+05, 1e+05]"},
        // every effect's times
        BadValue{kBadTorchBase + "    start_sec: 1e300\n", 5, "effects[0].start_sec",
                 "expected [0, 1e+06]"},
        BadValue{kBadTorchBase + "    stop_sec: 1e300\n", 5, "effects[0].stop_sec",
                 "expected [0, 1e+06]"},
        BadValue{kBadTorchBase + "    fade_in_sec: 1e300\n", 5, "effects[0].fade_in_sec",
                 "expected [0, 1e+06]"},
        BadValue{"effects:\n  - {name: haze, type: fog, mor_m: 80, "
                 "region: {min: [0, 0, 0], max: [1e300, 1, 1]}}\n",
                 2, "effects[0].region.max", "each [-1e+05, 1e+05]"},
        // fog: its layer and its visibility
        BadValue{"effects:\n  - name: haze\n    type: fog\n    mor_m: 1e300\n", 4,
                 "effects[0].mor_m", "expected [0.001, 1e+05]"},
        BadValue{"effects:\n  - name: haze\n    type: fog\n    mor_m: 80\n"
                 "    height_falloff_per_m: 1e300\n",
                 5, "effects[0].height_falloff_per_m", "expected [0, 1000]"},
        BadValue{"effects:\n  - name: haze\n    type: fog\n    mor_m: 80\n"
                 "    base_height_m: -1e300\n",
                 5, "effects[0].base_height_m", "expected [-1e+05, 1e+05]"},
        // smoke and fire fluids
        BadValue{
            kBadPlumeBase + "    buoyancy_m_s2: 1e308\n    emitters: [{position: [0, 0, 0.2]}]\n",
            6, "effects[0].buoyancy_m_s2", "expected [0, 1000]"},
        BadValue{
            kBadPlumeBase + "    cooling_per_s: 1e308\n    emitters: [{position: [0, 0, 0.2]}]\n",
            6, "effects[0].cooling_per_s", "expected [0, 1000]"},
        BadValue{kBadPlumeBase + "    emitters:\n      - {position: [0, 0, 0.2], rate: 1e300}\n", 7,
                 "effects[0].emitters[0].rate", "expected [0, 1000]"},
        BadValue{
            kBadPlumeBase + "    emitters:\n      - {position: [0, 0, 0.2], radius_m: 1e300}\n", 7,
            "effects[0].emitters[0].radius_m", "expected (0, 1e+05]"},
        BadValue{"effects:\n  - name: puff\n    type: smoke\n    mode: noise\n"
                 "    region: {min: [-1, -1, 0], max: [1, 1, 2]}\n    noise_scale_m: 1e300\n",
                 6, "effects[0].noise_scale_m", "expected (0, 1e+05]"},
        BadValue{"effects:\n  - name: flame\n    type: fire\n"
                 "    region: {min: [-1, -1, 0], max: [1, 1, 2]}\n"
                 "    emitters: [{position: [0, 0, 0.2]}]\n    glow_light_radius_m: 1e300\n",
                 6, "effects[0].glow_light_radius_m", "expected [0, 1e+05]"},
        // light events and wetness
        BadValue{"effects:\n  - name: blink\n    type: light_event\n    light: '*'\n"
                 "    recovery_sec: 1e300\n",
                 5, "effects[0].recovery_sec", "expected [0, 1e+06]"},
        BadValue{"effects:\n  - {name: storm, type: rain, rate_mm_h: 5}\n  - name: wet\n"
                 "    type: wetness\n    rain: storm\n    drying_time_sec: 1e300\n",
                 6, "effects[1].drying_time_sec", "expected (0, 1e+06]"},
        // agents: positions of 1e300 m
        BadValue{"agents:\n  - name: bob\n    waypoints: [[0, 0], [1e300, 0]]\n", 3,
                 "agents[0].waypoints[1]", "each in [-100000, 100000]"},
        BadValue{kBadAgentBase + "    floor_z: 1e300\n", 4, "agents[0].floor_z",
                 "expected a height in [-100000, 100000] m"},
        BadValue{kBadAgentBase + "    speed_m_s: 1e300\n", 4, "agents[0].speed_m_s",
                 "expected (0, 20] m/s"},
        // metrics: a point 1e300 m away, a debounce longer than any run
        BadValue{"metrics:\n  series:\n    - {name: g, type: distance, body: r/b, "
                 "to_point: [1e300, 0, 0]}\n",
                 3, "metrics.series[0].to_point", "each in [-1e+05, 1e+05]"},
        BadValue{"metrics:\n  series:\n    - {name: c, type: contacts, debounce_sec: 1e300}\n", 3,
                 "metrics.series[0].debounce_sec", "expected a number in [0, 1e+06] (s)"},
        // sensors: latency, rotation; LiDAR ranges (a rate above the physics rate samples every
        // step)
        BadValue{kBadSensorBase + "    latency_sec: 1e300\n", 5, "sensors[0].latency_sec",
                 "expected a number in [0, 3600] (s)"},
        BadValue{kBadSensorBase + "    pose: {rpy_deg: [0, 1e308, 0]}\n", 5,
                 "sensors[0].pose.rpy_deg", "expected each of the 3 numbers in [-360, 360] (deg)"},
        BadValue{
            "sensors:\n  - name: l\n    type: lidar\n    preset: velodyne_vlp16\n    body: world\n"
            "    max_range_m: 1e300\n",
            6, "sensors[0].max_range_m", "expected a number in [0, 1e+05] (m)"}));

// a world file of `n` lines: `body` padded at its start with comment lines
std::string WorldOfLines(int n, const std::string& body) {
  std::string text;
  const int body_lines = static_cast<int>(std::count(body.begin(), body.end(), '\n'));
  for (int i = 0; i < n - body_lines; ++i) text += "# filler\n";
  return text + body;
}

TEST(WorldFileLines, NoErrorCitesALinePastTheLastOne) {
  const penumbra::testing::TempDir dir;
  // an unclosed flow list ends at the end of the input: yaml-cpp marks the line after the last
  const std::string unclosed = dir.Write("unclosed.yaml", WorldOfLines(127, "cameras: [\n\n"));
  // a file of comments only: its null root took the mark of the end of the input
  const std::string empty = dir.Write("empty.yaml", WorldOfLines(127, "\n"));
  for (const auto& [file, line] : {std::pair{unclosed, 127}, std::pair{empty, 1}}) {
    try {
      LoadWorldFile(file);
      ADD_FAILURE() << "no ConfigError for " << file;
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.file(), file) << e.what();
      EXPECT_EQ(e.line(), line) << e.what();
    }
  }
}

}  // namespace
}  // namespace penumbra
