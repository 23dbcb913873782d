// who made a contact between the robot and an NPC (campaign/nav_metrics.h AgentMadeContact):
// two scripted runs through the real physics and the contacts metric (metrics/metrics_sink.h
// writes each episode's approach speeds), judged as the nav harness judges them: the rover
// driven into a standing person is the robot's collision; a person walking into the standing
// rover is an agent contact.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <sstream>

#include "common/run_loop.h"
#include "common/temp_dir.h"
#include "penumbra/campaign/nav_metrics.h"
#include "penumbra/metrics/metrics_sink.h"
#include "penumbra/physics/physics_source.h"
#include "penumbra/session/session.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

constexpr const char* kAttributionArena = R"(<mujoco model="arena">
  <worldbody>
    <geom name="floor" type="plane" size="6 6 0.1"/>
    <geom name="wall_n" type="box" pos="0 5 0.5" size="5 0.1 0.5"/>
    <geom name="wall_s" type="box" pos="0 -5 0.5" size="5 0.1 0.5"/>
  </worldbody>
</mujoco>)";

// the rover at the origin heading +x (driven at 0.5 m/s to x = 3 when `drive`), one person
// with `agent_yaml`, and the nav harness's contacts metric (campaign/nav_job.cc)
std::string AttributionWorld(const std::string& agent_yaml) {
  return std::string(R"(seed: 1
duration_sec: 4
physics: {timestep_sec: 0.002}
mjcf_cameras: {enabled: false}
robots:
  - name: rover
    file: )") +
         PENUMBRA_SOURCE_DIR + R"(/worlds/models/rover.xml
    controller:
      type: waypoint_follower
      base_body: chassis
      left_actuator: left_wheel
      right_actuator: right_wheel
      wheel_radius_m: 0.05
      track_width_m: 0.3
      speed_m_s: 0.5
      waypoints: [[3.0, 0.0]]
      loop: false
models:
  - {name: arena, file: arena.xml}
agents:
  - )" + agent_yaml +
         R"(
metrics:
  rate_hz: 50
  series:
    - name: nav_contacts
      type: contacts
      min_force_N: 1
      debounce_sec: 0
      between: [{a: "rover/*", b: "*"}]
      exclude: [{a: "rover/left_wheel", b: "arena/floor"}, {a: "rover/right_wheel", b: "arena/floor"}, {a: "rover/chassis", b: "arena/floor"}]
      self_contacts: false
      pair: body
)";
}

// runs the world (controllers on or off) and reads the contact intervals as the harness does:
// the robot's parts named by the robot
std::vector<ContactInterval> AttributionRun(const std::string& agent_yaml, bool drive) {
  testing::TempDir dir;
  std::ofstream(dir.path() / "arena.xml") << kAttributionArena;
  const WorldConfig world =
      ParseWorld(AttributionWorld(agent_yaml), (dir.path() / "world.yaml").string());
  SessionOptions options;
  options.build_renderer = false;
  options.add_controllers = drive;
  Session session(world, options);
  std::unique_ptr<MetricsSink> sink =
      MakeMetricsSink(world, session.sim(), (dir.path() / "out").string(), MetricsMode::kDynamics);
  PhysicsSource source(&session.sim());
  const LoopFinish f = testing::RunLoop(&source, {sink.get()}, world.duration_sec);
  EXPECT_FALSE(f.error);
  std::ifstream in(dir.path() / "out" / "metrics" / "nav_contacts_episodes.csv");
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line,
            "episode,a,b,start_sec,end_sec,peak_force_N,a_speed_toward_b_m_s,b_speed_toward_a_m_s");
  std::vector<ContactInterval> out;
  while (std::getline(in, line)) {
    std::stringstream s(line);
    std::vector<std::string> f;
    for (std::string cell; std::getline(s, cell, ',');) f.push_back(cell);
    if (f.size() != 8) continue;
    ContactInterval c{f[1], f[2], std::stod(f[3]), std::stod(f[4])};
    c.a_toward_b_m_s = std::stod(f[6]);
    c.b_toward_a_m_s = std::stod(f[7]);
    std::printf("  %s | %s from %.3f s: %s -> %.3f m/s, %s -> %.3f m/s\n", c.a.c_str(), c.b.c_str(),
                c.start_sec, c.a.c_str(), c.a_toward_b_m_s, c.b.c_str(), c.b_toward_a_m_s);
    out.push_back(c);
  }
  NameContactSides("rover", &out);  // as the harness does
  return out;
}

TEST(NavContactAttribution, TheRobotDrivingIntoAStandingPersonCausedTheCollision) {
  // a person standing at x = 1 facing +x (its delay keeps it at its first waypoint)
  const std::vector<ContactInterval> c = AttributionRun(
      "{name: bystander, type: person, waypoints: [[1.0, 0.0], [2.0, 0.0]], route: once, "
      "start_delay_sec: 3600, height_m: 1.75}",
      true);
  ASSERT_FALSE(c.empty()) << "the rover reaches the person";
  EXPECT_EQ(c.front().b, "agents/bystander");
  EXPECT_GT(c.front().a_toward_b_m_s, 0.3) << "the rover drove at 0.5 m/s";
  EXPECT_EQ(c.front().b_toward_a_m_s, 0) << "a standing person does not move";
  const CollisionCounts n = CountCollisionsByCause(c, 0.5, 100, "rover");
  std::printf("%zu intervals: %d agent contact(s), %d robot collision(s)\n", c.size(), n.agent,
              n.robot);
  EXPECT_EQ(n.robot, 1);
  EXPECT_EQ(n.agent, 0);
}

TEST(NavContactAttribution, APersonWalkingIntoTheStandingRobotMadeTheContact) {
  // the rover stands (no controller); a person walks from x = 3 towards -x at 1.3 m/s
  const std::vector<ContactInterval> c = AttributionRun(
      "{name: walker, type: person, waypoints: [[3.0, 0.0], [-3.0, 0.0]], route: once, "
      "speed_m_s: 1.3, height_m: 1.75}",
      false);
  ASSERT_FALSE(c.empty()) << "the person reaches the rover";
  EXPECT_EQ(c.front().b, "agents/walker");
  EXPECT_NEAR(c.front().b_toward_a_m_s, 1.3, 0.05) << "the person's root speed towards it";
  EXPECT_LT(std::abs(c.front().a_toward_b_m_s), 0.05) << "the rover stood still";
  // counted until the person has passed (x = -0.9 m at 3 s): on MuJoCo 4 the push tips the
  // rover over afterwards and its camera mount hits the floor from 3.08 s, a contact of the
  // robot's own that the judge counts as the robot's
  const CollisionCounts n = CountCollisionsByCause(c, 0.5, 3.0, "rover");
  std::printf("%zu intervals: %d agent contact(s), %d robot collision(s)\n", c.size(), n.agent,
              n.robot);
  EXPECT_EQ(n.agent, 1) << "the person's limbs touching the rover are one contact";
  EXPECT_EQ(n.robot, 0);
}

TEST(NavContactAttribution, TheRuleOnHandMadeIntervals) {
  // the judge's names: the robot's parts are the robot, an agent's limbs the agent
  std::vector<ContactInterval> named = {{"go1/FR_calf", "agents/p/shin_l", 0, 1},
                                        {"agents/lift/wheel_fl", "go1/trunk", 0, 1},
                                        {"go1/trunk", "room/table", 0, 1}};
  NameContactSides("go1", &named);
  EXPECT_EQ(named[0].a, "go1");
  EXPECT_EQ(named[0].b, "agents/p");
  EXPECT_EQ(named[1].a, "agents/lift");
  EXPECT_EQ(named[1].b, "go1");
  EXPECT_EQ(named[2].b, "room/table");
  // agent faster towards the robot than the robot towards it, above 0.1 m/s: the agent's
  ContactInterval c{"go1", "agents/p/shin_l", 1.0, 1.2};
  c.a_toward_b_m_s = 0.2;
  c.b_toward_a_m_s = 1.0;
  EXPECT_TRUE(AgentMadeContact(c, "go1"));
  std::swap(c.a, c.b);
  std::swap(c.a_toward_b_m_s, c.b_toward_a_m_s);
  EXPECT_TRUE(AgentMadeContact(c, "go1"));  // either side order
  // the robot faster: the robot's
  c.a_toward_b_m_s = 0.5;
  c.b_toward_a_m_s = 0.6;
  EXPECT_FALSE(AgentMadeContact(c, "go1"));
  // a slow agent (below 0.1 m/s) never makes a contact, even against a robot moving away
  ContactInterval slow{"go1", "agents/p", 2.0, 2.1, -0.2, 0.05};
  EXPECT_FALSE(AgentMadeContact(slow, "go1"));
  // a wall is always the robot's; no robot name: no attribution
  ContactInterval wall{"go1", "room/wall", 3.0, 3.1, 0.0, 2.0};
  EXPECT_FALSE(AgentMadeContact(wall, "go1"));
  EXPECT_FALSE(AgentMadeContact(ContactInterval{"go1", "agents/p", 1, 2, 0, 1}, ""));
  // debounced runs take their first interval's cause; robot + agent = CountCollisions
  const std::vector<ContactInterval> list = {
      {"go1", "agents/p", 1.0, 1.1, 0.0, 1.2},   // agent walks in
      {"go1", "agents/p", 1.3, 1.4, 0.9, 0.0},   // chatter of the same contact
      {"go1", "agents/p", 5.0, 5.1, 0.8, 0.0},   // later: the robot drives in
      {"go1", "room/wall", 2.0, 2.5, 0.0, 0.0},  // a wall
  };
  const CollisionCounts n = CountCollisionsByCause(list, 0.5, 100, "go1");
  EXPECT_EQ(n.agent, 1);
  EXPECT_EQ(n.robot, 2);
  EXPECT_EQ(n.agent + n.robot, CountCollisions(list, 0.5, 100));
  // the episode's metrics: SC counts the robot's collisions only
  NavEpisodeTask task;
  task.goal_x = 1;
  task.robot = "go1";
  const std::vector<NavPoseSample> poses = {{0, 0, 0, 0.3, 1, 0, 0, 0}, {6, 1, 0, 0.3, 1, 0, 0, 0}};
  const NavEpisodeMetrics m = EvaluateNavEpisode(poses, list, task, true);
  EXPECT_EQ(m.collisions, 2);
  EXPECT_EQ(m.agent_contacts, 1);
  EXPECT_DOUBLE_EQ(m.sc, 1.0 / 3.0);
}

}  // namespace
}  // namespace penumbra
