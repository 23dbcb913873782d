// world-file `metrics:`: parsing, defaults, and ConfigErrors naming file, line and key.
#include "penumbra/world/metrics_config.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "penumbra/core/error.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

class MetricsConfigTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("penumbra_metrics_config_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    std::ofstream(dir_ / "m.xml") << "<mujoco><worldbody><body name=\"b\"><freejoint/>"
                                     "<geom size=\"0.1\"/></body></worldbody></mujoco>";
  }
  void TearDown() override { fs::remove_all(dir_); }
  // line 1-3: the robot; `text` starts on line 4
  WorldConfig Parse(const std::string& text) {
    return ParseWorld("robots:\n  - name: r\n    file: m.xml\n" + text,
                      (dir_ / "world.yaml").string());
  }
  std::string Error(const std::string& text) {
    try {
      Parse(text);
    } catch (const ConfigError& e) {
      return e.what();
    }
    return "";
  }
  fs::path dir_;
};

TEST_F(MetricsConfigTest, ParsesEveryType) {
  const WorldConfig w = Parse(R"(metrics:
  rate_hz: 20
  series:
    - {name: pose, type: body_pose, bodies: [r/b], rate_hz: 100}
    - {name: twist, type: body_twist, bodies: ["r/*"]}
    - {name: q, type: joint_position, joints: [r/*]}
    - {name: qd, type: joint_velocity, joints: [r/*]}
    - {name: tau, type: joint_torque, joints: [r/*]}
    - {name: goal, type: distance, body: r/b, to_point: [1, 2, 3]}
    - {name: goal2, type: distance, body: r/b, to_body: world}
    - {name: s, type: sensor, sensors: ["*"]}
    - {name: track, type: tracking_error, robot: r}
    - name: bumps
      type: contacts
      min_force_N: 5
      debounce_sec: 0.25
      between: [{a: "r/*"}]
      exclude: [{a: "r/*", b: "room/floor"}]
      self_contacts: true
      pair: geom
      detect_hz: 100
)");
  const MetricsConfig& m = w.metrics;
  EXPECT_TRUE(m.enabled());
  EXPECT_EQ(m.rate_hz, 20);
  ASSERT_EQ(m.series.size(), 10u);
  EXPECT_EQ(m.series[0].kind, MetricKind::kBodyPose);
  EXPECT_EQ(m.RateOf(m.series[0]), 100);
  EXPECT_EQ(m.RateOf(m.series[1]), 20) << "the section's rate by default";
  EXPECT_EQ(m.series[2].joints, std::vector<std::string>{"r/*"});
  EXPECT_EQ(m.series[4].kind, MetricKind::kJointTorque);
  ASSERT_TRUE(m.series[5].to_point_m);
  EXPECT_EQ(*m.series[5].to_point_m, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(m.series[6].to_body, "world");
  EXPECT_EQ(m.series[8].robot, "r");
  const MetricConfig& c = m.series[9];
  EXPECT_EQ(c.kind, MetricKind::kContacts);
  EXPECT_EQ(c.min_force_N, 5);
  EXPECT_EQ(c.debounce_sec, 0.25);
  ASSERT_EQ(c.between.size(), 1u);
  EXPECT_EQ(c.between[0].a, "r/*");
  EXPECT_EQ(c.between[0].b, "*") << "a missing side matches anything";
  ASSERT_EQ(c.exclude.size(), 1u);
  EXPECT_EQ(c.exclude[0].b, "room/floor");
  EXPECT_TRUE(c.self_contacts);
  EXPECT_TRUE(c.geom_pairs);
  EXPECT_EQ(c.detect_hz, 100);
}

TEST_F(MetricsConfigTest, DefaultsAndNoSection) {
  EXPECT_FALSE(Parse("").metrics.enabled());
  const WorldConfig w = Parse("metrics:\n  series:\n    - {name: c, type: contacts}\n");
  const MetricConfig& c = w.metrics.series.at(0);
  EXPECT_EQ(w.metrics.rate_hz, 50);
  EXPECT_EQ(c.min_force_N, 1.0);
  EXPECT_EQ(c.debounce_sec, 0.1);
  EXPECT_TRUE(c.between.empty());
  EXPECT_FALSE(c.self_contacts);
  EXPECT_FALSE(c.geom_pairs);
  EXPECT_EQ(c.detect_hz, 0) << "every physics step";
}

TEST_F(MetricsConfigTest, ErrorsNameFileLineAndKey) {
  const std::string file = (dir_ / "world.yaml").string();
  // unknown key of the section (line 6)
  const std::string unknown = Error("metrics:\n  rate_hz: 10\n  serie: []\n");
  EXPECT_NE(unknown.find(file + ":6: metrics.serie: unknown key"), std::string::npos) << unknown;
  // a key of another type
  const std::string other =
      Error("metrics:\n  series:\n    - {name: p, type: body_pose, bodies: [a], joints: [b]}\n");
  EXPECT_NE(other.find(":6: metrics.series[0].joints: does not apply to a body_pose metric"),
            std::string::npos)
      << other;
  // unknown type
  const std::string type = Error("metrics:\n  series:\n    - {name: p, type: bodypose}\n");
  EXPECT_NE(type.find("metrics.series[0].type: unknown value 'bodypose'"), std::string::npos)
      << type;
  // a required key
  const std::string req = Error("metrics:\n  series:\n    - {name: p, type: body_pose}\n");
  EXPECT_NE(req.find("metrics.series[0]"), std::string::npos) << req;
  EXPECT_NE(req.find("bodies"), std::string::npos) << req;
  // ranges (validated after parsing, still with the line)
  const std::string rate = Error(
      "metrics:\n  series:\n    - name: p\n      type: body_pose\n      bodies: [r/b]\n"
      "      rate_hz: 0\n");
  EXPECT_NE(rate.find(file + ":9: metrics.series[0].rate_hz: got 0; expected (0, 10000] Hz"),
            std::string::npos)
      << rate;
  const std::string force =
      Error("metrics:\n  series:\n    - {name: c, type: contacts, min_force_N: -1}\n");
  EXPECT_NE(force.find("metrics.series[0].min_force_N: got -1; expected a number in [0, 1e+09]"),
            std::string::npos)
      << force;
  const std::string dup = Error(
      "metrics:\n  series:\n    - {name: c, type: contacts}\n    - {name: c, type: contacts}\n");
  EXPECT_NE(dup.find(":7: metrics.series[1].name: duplicate name 'c'"), std::string::npos) << dup;
  const std::string name = Error("metrics:\n  series:\n    - {name: a/b, type: contacts}\n");
  EXPECT_NE(name.find("metrics.series[0].name: 'a/b' is not a valid metric name"),
            std::string::npos)
      << name;
  const std::string both = Error(
      "metrics:\n  series:\n    - {name: d, type: distance, body: r/b, to_body: world, "
      "to_point: [0, 0, 0]}\n");
  EXPECT_NE(both.find("exactly one of to_body and to_point"), std::string::npos) << both;
  const std::string pair =
      Error("metrics:\n  series:\n    - {name: c, type: contacts, pair: link}\n");
  EXPECT_NE(pair.find("metrics.series[0].pair: unknown value 'link'; expected one of: body, geom"),
            std::string::npos)
      << pair;
}

}  // namespace
}  // namespace penumbra
