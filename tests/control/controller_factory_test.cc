// controller factory and parameter validation: unknown types and keys, bad values,
// robot prefixes, and the error format "file:line: robots[R].controller.key: ...".

#include "penumbra/control/controller_factory.h"

#include <gtest/gtest.h>

#include <cmath>

#include "penumbra/config/yaml_document.h"
#include "penumbra/control/controller_capabilities.h"
#include "penumbra/control/waypoint_follower.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

constexpr const char* kGood = R"(type: waypoint_follower
base_body: chassis
left_actuator: left_wheel
right_actuator: right_wheel
wheel_radius_m: 0.05
track_width_m: 0.3
speed_m_s: 0.5
max_yaw_rate_deg_s: 90
waypoints: [[1.0, 0.0], [1.0, 1.0]]
loop: true
tolerance_m: 0.15
)";

ControllerConfig Config(const std::string& yaml, const std::string& type = "waypoint_follower") {
  ControllerConfig c;
  c.type = type;
  c.params = ParseYaml(yaml);
  c.line = 21;
  return c;
}

// the ConfigError MakeController throws for `yaml`
ConfigError ErrorFor(const std::string& yaml, const std::string& type = "waypoint_follower") {
  try {
    MakeController(Config(yaml, type), "rover", "worlds/w.yaml");
  } catch (const ConfigError& e) {
    return e;
  }
  ADD_FAILURE() << "no ConfigError for:\n" << yaml;
  return ConfigError("", 0, "", "");
}

std::string Replace(std::string s, const std::string& from, const std::string& to) {
  const size_t p = s.find(from);
  EXPECT_NE(p, std::string::npos) << from;
  return s.replace(p, from.size(), to);
}

TEST(ControllerFactory, BuildsWaypointFollowerWithPrefixedNames) {
  std::unique_ptr<Controller> c = MakeController(Config(kGood), "rover", "w.yaml");
  auto* f = dynamic_cast<WaypointFollower*>(c.get());
  ASSERT_NE(f, nullptr);
  EXPECT_EQ(f->type(), "waypoint_follower");
  EXPECT_EQ(f->params().base_body, "rover/chassis");
  EXPECT_EQ(f->params().left_actuator, "rover/left_wheel");
  EXPECT_EQ(f->params().right_actuator, "rover/right_wheel");
  EXPECT_EQ(f->params().waypoints.size(), 2u);
  EXPECT_EQ(f->params().waypoints[1], Eigen::Vector2d(1, 1));
  EXPECT_EQ(f->params().track_width_m, 0.3);
  EXPECT_TRUE(f->params().loop);
  EXPECT_EQ(f->rate_hz(), 50);
  EXPECT_EQ(f->context().key, "robots[rover].controller");
  const auto names = f->RequiredNames();
  ASSERT_EQ(names.size(), 3u);
  EXPECT_EQ(names[0].kind, ModelObject::kBody);
  EXPECT_EQ(names[0].key, "base_body");
  // no robot name: no prefix
  auto bare = MakeController(Config(kGood), "", "w.yaml");
  EXPECT_EQ(dynamic_cast<WaypointFollower*>(bare.get())->params().base_body, "chassis");
}

// a differential drive takes twists without sideways speed and routes; its command names
// (model_info's "commands") come from those capabilities
TEST(ControllerFactory, WaypointFollowerIsATwistAndWaypointTarget) {
  std::unique_ptr<Controller> c = MakeController(Config(kGood), "rover", "w.yaml");
  TwistTarget* twist = AsTwistTarget(*c);
  ASSERT_NE(twist, nullptr);
  ASSERT_NE(AsWaypointTarget(*c), nullptr);
  EXPECT_EQ(AsJointTarget(*c), nullptr);
  EXPECT_FALSE(twist->lateral());
  EXPECT_EQ(ControllerCommands(*c), (std::vector<std::string>{"twist", "waypoints"}));
  EXPECT_THROW(twist->SetTwist(TrotCommand{0.5, 0.1, 0}), Error);
  EXPECT_THROW(twist->SetTwist(TrotCommand{NAN, 0, 0}), Error);
  twist->SetTwist(TrotCommand{0.5, 0, 0.2});
  twist->ClearTwist();
  EXPECT_THROW(AsWaypointTarget(*c)->SetWaypoints({}, false), Error);
}

TEST(ControllerFactory, OptionalKeysHaveDefaults) {
  const std::string yaml = R"(base_body: c
left_actuator: l
right_actuator: r
wheel_radius_m: 0.1
track_width_m: 0.5
waypoints: [[0, 0]]
)";
  auto c = MakeController(Config(yaml), "r", "w.yaml");
  const auto& p = dynamic_cast<WaypointFollower*>(c.get())->params();
  EXPECT_EQ(p.speed_m_s, 0.5);
  EXPECT_EQ(p.max_yaw_rate_deg_s, 90);
  EXPECT_TRUE(p.loop);
  EXPECT_EQ(p.tolerance_m, 0.15);
  EXPECT_EQ(p.rate_hz, 50);
}

TEST(ControllerFactory, EmptyTypeMeansNoController) {
  EXPECT_EQ(MakeController(Config("", ""), "rover", "w.yaml"), nullptr);
}

TEST(ControllerFactory, ParamsMustBeAMappingOrNothing) {
  // a list or a scalar in place of the block's mapping
  EXPECT_EQ(std::string(ErrorFor("[a, b]").what()),
            "worlds/w.yaml:21: robots[rover].controller: got a list of 2 items; expected a "
            "mapping of controller parameters");
  EXPECT_EQ(std::string(ErrorFor("fast").what()),
            "worlds/w.yaml:21: robots[rover].controller: got 'fast'; expected a mapping of "
            "controller parameters");
  // no parameters at all (a null node): the required keys are reported missing
  ControllerConfig none;
  none.type = "waypoint_follower";
  none.line = 4;
  try {
    MakeController(none, "rover", "w.yaml");
    ADD_FAILURE() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()),
              "w.yaml:4: robots[rover].controller.base_body: missing; expected a name");
  }
}

TEST(ControllerFactory, UnknownTypeNamesKnownTypes) {
  const ConfigError e = ErrorFor(kGood, "teleport");
  EXPECT_EQ(e.file(), "worlds/w.yaml");
  EXPECT_EQ(e.line(), 21);
  EXPECT_EQ(e.key(), "robots[rover].controller.type");
  EXPECT_NE(std::string(e.what()).find("waypoint_follower"), std::string::npos) << e.what();
}

TEST(ControllerFactory, UnknownKeysAreRejected) {
  const ConfigError e = ErrorFor(std::string(kGood) + "sped_m_s: 2\nfoo: 1\n");
  EXPECT_EQ(e.key(), "robots[rover].controller.sped_m_s");
  const std::string msg = e.what();
  EXPECT_NE(msg.find("'sped_m_s', 'foo'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("speed_m_s"), std::string::npos) << msg;  // lists the allowed keys
}

TEST(ControllerFactory, BadValuesNameKeyAndExpectation) {
  struct Case {
    std::string from, to, key, expect;
  };
  const std::vector<Case> cases = {
      {"speed_m_s: 0.5", "speed_m_s: -1", "speed_m_s", "> 0"},
      {"speed_m_s: 0.5", "speed_m_s: fast", "speed_m_s", "'fast'"},
      {"wheel_radius_m: 0.05", "wheel_radius_m: 0", "wheel_radius_m", "> 0"},
      {"wheel_radius_m: 0.05\n", "", "wheel_radius_m", "missing"},
      {"track_width_m: 0.3", "track_width_m: .nan", "track_width_m", "number"},
      {"loop: true", "loop: maybe", "loop", "true or false"},
      {"waypoints: [[1.0, 0.0], [1.0, 1.0]]", "waypoints: []", "waypoints", "at least 1"},
      {"waypoints: [[1.0, 0.0], [1.0, 1.0]]", "waypoints: [[1.0, 0.0], [1.0]]", "waypoints[1]",
       "[x, y]"},
      {"waypoints: [[1.0, 0.0], [1.0, 1.0]]", "waypoints: [[1.0, 0.0], [1.0, y]]", "waypoints[1]",
       "a number (m) in [-100000, 100000]"},
      {"waypoints: [[1.0, 0.0], [1.0, 1.0]]", "waypoints: 3", "waypoints", "list"},
      {"base_body: chassis", "base_body: [a, b]", "base_body", "name"},
      {"right_actuator: right_wheel", "right_actuator: left_wheel", "right_actuator", "different"},
      {"tolerance_m: 0.15", "tolerance_m: 0", "tolerance_m", "> 0"},
  };
  for (const Case& c : cases) {
    const ConfigError e = ErrorFor(Replace(kGood, c.from, c.to));
    EXPECT_EQ(e.key(), "robots[rover].controller." + c.key) << c.to << ": " << e.what();
    EXPECT_NE(std::string(e.what()).find(c.expect), std::string::npos) << c.to << ": " << e.what();
    EXPECT_EQ(e.line(), 21);
  }
}

}  // namespace
}  // namespace penumbra
