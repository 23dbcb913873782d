// the waypoint follower driving a simulated differential-drive robot (built from a
// world-file style controller block through the factory, with composer-style names).

#include <gtest/gtest.h>

#include <cmath>

#include "penumbra/config/yaml_document.h"
#include "penumbra/control/controller_factory.h"
#include "penumbra/control/waypoint_follower.h"
#include "penumbra/core/error.h"
#include "penumbra/physics/simulation.h"

namespace penumbra {
namespace {

// box chassis, two hinge wheels with velocity actuators (axes along +y: positive =
// forward), a low-friction caster sphere; names prefixed "rover/" as the composer does.
constexpr const char* kRoverXml = R"(
<mujoco model="rover">
  <option timestep="0.002"/>
  <worldbody>
    <geom name="floor" type="plane" size="10 10 0.1"/>
    <body name="rover/chassis" pos="0 0 0.06">
      <freejoint name="rover/root"/>
      <geom name="rover/hull" type="box" size="0.15 0.1 0.03" mass="2"/>
      <geom name="rover/caster" type="sphere" size="0.025" pos="-0.12 0 -0.035" mass="0.05"
            friction="0.001 0.001 0.001"/>
      <body name="rover/left_wheel_link" pos="0.05 0.15 -0.01">
        <joint name="rover/left_wheel_joint" type="hinge" axis="0 1 0" damping="0.001" armature="0.01"/>
        <geom type="cylinder" size="0.05 0.02" zaxis="0 1 0" mass="0.2" friction="1.5 0.005 0.0001"/>
      </body>
      <body name="rover/right_wheel_link" pos="0.05 -0.15 -0.01">
        <joint name="rover/right_wheel_joint" type="hinge" axis="0 1 0" damping="0.001" armature="0.01"/>
        <geom type="cylinder" size="0.05 0.02" zaxis="0 1 0" mass="0.2" friction="1.5 0.005 0.0001"/>
      </body>
    </body>
  </worldbody>
  <actuator>
    <velocity name="rover/left_wheel" joint="rover/left_wheel_joint" kv="0.5"/>
    <velocity name="rover/right_wheel" joint="rover/right_wheel_joint" kv="0.5"/>
  </actuator>
</mujoco>)";

ControllerConfig SquareConfig(bool loop) {
  ControllerConfig cfg;
  cfg.type = "waypoint_follower";
  cfg.line = 12;
  cfg.params = ParseYaml(std::string(R"(type: waypoint_follower
base_body: chassis
left_actuator: left_wheel
right_actuator: right_wheel
wheel_radius_m: 0.05
track_width_m: 0.3
speed_m_s: 0.5
max_yaw_rate_deg_s: 90
waypoints: [[1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.0, 0.0]]
tolerance_m: 0.15
loop: )") + (loop ? "true" : "false") +
                         "\n");
  return cfg;
}

TEST(WaypointFollowerSim, DrivesASquareReachingEveryWaypoint) {
  Simulation sim = Simulation::LoadFromString(kRoverXml);
  std::unique_ptr<Controller> c = MakeController(SquareConfig(false), "rover", "world.yaml");
  auto* follower = dynamic_cast<WaypointFollower*>(c.get());
  ASSERT_NE(follower, nullptr);
  sim.AddController(std::move(c));

  const std::vector<Eigen::Vector2d> wps = {{1, 0}, {1, 1}, {0, 1}, {0, 0}};
  const int chassis = sim.scene().FindBody("rover/chassis");
  size_t next = 0;  // next waypoint the chassis has to come within tolerance of
  std::vector<double> reached_at;
  double finished_at = -1;
  WorldSnapshot snap;
  while (sim.time() < 40.0) {
    sim.Step();
    sim.Snapshot(&snap);
    const Pose& X = snap.X_WB[chassis];
    ASSERT_GT(X.linear()(2, 2), 0.9) << "chassis tipped over at t = " << sim.time();
    if (next < wps.size() && (X.translation().head<2>() - wps[next]).norm() < 0.15) {
      reached_at.push_back(sim.time());
      ++next;
    }
    if (follower->finished() && finished_at < 0) finished_at = sim.time();
    if (finished_at >= 0 && sim.time() > finished_at + 1.0) break;
  }
  ASSERT_EQ(reached_at.size(), wps.size()) << "reached " << reached_at.size() << " waypoints";
  EXPECT_EQ(follower->waypoints_reached(), 4);
  EXPECT_TRUE(follower->finished());
  // 4 m of path at 0.5 m/s plus four turns of about 90 deg at <= 90 deg/s
  EXPECT_LT(reached_at.back(), 16.0);
  // after the last waypoint the robot stops near it
  const Eigen::Vector2d p = snap.X_WB[chassis].translation().head<2>();
  EXPECT_LT(p.norm(), 0.3) << p.transpose();
  const Eigen::Vector3d v = Eigen::Map<const Eigen::Vector3d>(sim.qvel().data());
  EXPECT_LT(v.norm(), 0.05);
}

TEST(WaypointFollowerSim, LoopKeepsGoing) {
  Simulation sim = Simulation::LoadFromString(kRoverXml);
  std::unique_ptr<Controller> c = MakeController(SquareConfig(true), "rover", "world.yaml");
  auto* follower = dynamic_cast<WaypointFollower*>(c.get());
  sim.AddController(std::move(c));
  while (sim.time() < 25.0) sim.Step();
  EXPECT_FALSE(follower->finished());
  EXPECT_GE(follower->waypoints_reached(), 6);  // into the second lap
}

TEST(WaypointFollowerSim, MissingNamesFailAtLoadListingAll) {
  ControllerConfig cfg = SquareConfig(false);
  cfg.params = ParseYaml(R"(base_body: hull_link
left_actuator: left_wheel
right_actuator: right_motor
wheel_radius_m: 0.05
track_width_m: 0.3
waypoints: [[1, 0]]
)");
  Simulation sim = Simulation::LoadFromString(kRoverXml);
  try {
    sim.AddController(MakeController(cfg, "rover", "world.yaml"));
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(e.file(), "world.yaml");
    EXPECT_EQ(e.line(), 12);
    EXPECT_EQ(e.key(), "robots[rover].controller");
    EXPECT_NE(msg.find("2 names not found"), std::string::npos) << msg;
    EXPECT_NE(msg.find("base_body: body 'rover/hull_link'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("right_actuator: actuator 'rover/right_motor'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("'rover/right_wheel'"), std::string::npos) << msg;  // hint
  }
}

TEST(WaypointFollowerSim, ActuatorMustDriveAHinge) {
  ControllerConfig cfg = SquareConfig(false);
  const char* xml = R"(
<mujoco><worldbody><body name="r/chassis"><freejoint/><geom type="box" size=".1 .1 .1"/>
  <body name="r/slider_link"><joint name="r/slide" type="slide"/><geom type="sphere" size=".01"/></body>
  <body name="r/wheel_link"><joint name="r/hinge"/><geom type="sphere" size=".01"/></body>
</body></worldbody>
<actuator><velocity name="r/left_wheel" joint="r/slide"/><velocity name="r/right_wheel" joint="r/hinge"/></actuator>
</mujoco>)";
  Simulation sim = Simulation::LoadFromString(xml);
  try {
    sim.AddController(MakeController(cfg, "r", "w.yaml"));
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "robots[r].controller.left_actuator");
  }
}

}  // namespace
}  // namespace penumbra
