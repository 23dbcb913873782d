#include "penumbra/effects/crowd_sim.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstring>

#include "penumbra/effects/agent_animation.h"
#include "penumbra/effects/orca.h"
#include "penumbra/effects/walkable_grid.h"

namespace penumbra {
namespace {

// two 6 x 4 m rooms side by side, a wall at x = 0 with a 1.2 m door at y in [1.4, 2.6], and a
// 1 x 1 m table in the left room at (-3, 2)
OccupancyGrid TwoRoomsGrid() {
  OccupancyGrid g;
  g.min_W = {-6.2, -0.2};
  g.cell_m = 0.1;
  g.nx = 124;
  g.ny = 44;
  g.blocked.assign(static_cast<size_t>(g.nx) * g.ny, 0);
  for (int iy = 0; iy < g.ny; ++iy)
    for (int ix = 0; ix < g.nx; ++ix) {
      const double x = g.min_W.x() + (ix + 0.5) * g.cell_m, y = g.min_W.y() + (iy + 0.5) * g.cell_m;
      const bool outer = x < -6.0 || x > 6.0 || y < 0.0 || y > 4.0;
      const bool wall = std::abs(x) < 0.1 && !(y > 1.4 && y < 2.6);
      const bool table = std::abs(x + 3) < 0.5 && std::abs(y - 2) < 0.5;
      g.blocked[iy * g.nx + ix] = outer || wall || table;
    }
  return g;
}

TEST(WalkableGridTest, InflatesByRadiusAndKeepsTheSeedsComponent) {
  const WalkableGrid person(TwoRoomsGrid(), 0.3, {-5, 1});
  EXPECT_TRUE(person.Walkable({-5, 1}));
  EXPECT_TRUE(person.Walkable({5, 3}));       // through the door
  EXPECT_FALSE(person.Walkable({-3, 2}));     // the table
  EXPECT_FALSE(person.Walkable({-3, 2.75}));  // 0.25 m from the table's edge
  EXPECT_TRUE(person.Walkable({-3, 2.85}));   // 0.35 m from it
  EXPECT_FALSE(person.Walkable({-5.8, 1}));   // 0.2 m from the outer wall
  // a 1.6 m wide body does not fit the 1.2 m door: the right room is another component
  const WalkableGrid wide(TwoRoomsGrid(), 0.8, {-5, 1});
  EXPECT_TRUE(wide.Walkable({-5, 1}));
  EXPECT_FALSE(wide.Walkable({3, 2}));
  // planning there ends at the walkable cell nearest the goal, on this side of the wall
  const auto plan = wide.Plan({-5, 1}, {3, 2});
  ASSERT_TRUE(plan.has_value());
  EXPECT_LT(plan->back().x(), 0.0);
}

TEST(WalkableGridTest, PlanGoesThroughTheDoorAroundTheTable) {
  const WalkableGrid g(TwoRoomsGrid(), 0.3, {-5, 1});
  const auto plan = g.Plan({-5, 2}, {5, 2});
  ASSERT_TRUE(plan.has_value());
  EXPECT_EQ(plan->front(), Eigen::Vector2d(-5, 2));
  EXPECT_EQ(plan->back(), Eigen::Vector2d(5, 2));
  double length = 0;
  for (size_t i = 0; i + 1 < plan->size(); ++i) {
    EXPECT_TRUE(g.SegmentWalkable((*plan)[i], (*plan)[i + 1]));
    length += ((*plan)[i + 1] - (*plan)[i]).norm();
  }
  // around the table (0.5 + 0.3 clear) costs a little more than the straight 10 m
  EXPECT_GT(length, 10.05);
  EXPECT_LT(length, 10.8);
}

TEST(OrcaTest, HeadOnPairPassesAndFreeAgentKeepsItsVelocity) {
  // nothing near: the preferred velocity
  EXPECT_TRUE(SolveOrcaVelocity({}, 1.5, {1, 0}).isApprox(Eigen::Vector2d(1, 0)));
  // too fast: clipped to the speed disc
  EXPECT_NEAR(SolveOrcaVelocity({}, 1.0, {3, 4}).norm(), 1.0, 1e-12);
  // head on at 4 m, 1 m/s each: the ORCA velocity leaves the collision course
  const Eigen::Vector2d va(1, 0), vb(-1, 0);
  const OrcaLine l = OrcaHalfPlane(va, {4, 0}, va - vb, 0.5, 5.0, 0.05, 0.5);
  const Eigen::Vector2d v = SolveOrcaVelocity({l}, 1.5, va);
  // with B's mirrored choice the relative velocity 2 v_y... lies outside the cone
  const Eigen::Vector2d rel = v - Eigen::Vector2d(-v.x(), -v.y());
  const double t_closest = std::max(0.0, Eigen::Vector2d(4, 0).dot(rel) / rel.squaredNorm());
  const double miss = (Eigen::Vector2d(4, 0) - t_closest * rel).norm();
  EXPECT_GE(miss, 0.5 - 1e-6);
  EXPECT_GT(std::abs(v.y()), 0.01);
}

TEST(OrcaTest, InfeasibleConstraintsGiveTheLeastViolation) {
  // two opposite half-planes that exclude each other: y >= 1 and y <= -1
  std::vector<OrcaLine> lines(2);
  lines[0].point = {0, 1};
  lines[0].direction = {1, 0};  // left of +x: y >= 1
  lines[1].point = {0, -1};
  lines[1].direction = {-1, 0};  // left of -x: y <= -1
  const Eigen::Vector2d v = SolveOrcaVelocity(lines, 2.0, {1, 0});
  EXPECT_NEAR(v.y(), 0.0, 1e-9);  // violates both by 1, the least possible largest violation
}

AgentConfig Walker(const std::string& name, std::vector<Eigen::Vector2d> points) {
  AgentConfig a;
  a.name = name;
  a.motion = AgentMotion::kCrowd;
  a.waypoints = std::move(points);
  a.speed_m_s = 1.3;
  a.pause_sec = 0.5;
  return a;
}

TEST(CrowdSimTest, CrossingWalkersStayWalkableAndApart) {
  auto person = std::make_shared<const WalkableGrid>(TwoRoomsGrid(), 0.3, Eigen::Vector2d(-5, 1));
  auto vehicle = std::make_shared<const WalkableGrid>(TwoRoomsGrid(), 0.7, Eigen::Vector2d(-5, 1));
  std::vector<AgentConfig> agents = {
      Walker("a", {{-5, 2}, {5, 2}}), Walker("b", {{5, 2.2}, {-5, 1.8}}),
      Walker("c", {{-4, 0.6}, {4, 3.4}}), Walker("d", {{4, 0.6}, {-4, 3.4}}),
      Walker("e", {{-1.5, 3.5}, {2, 0.5}})};
  agents[4].goals = AgentGoals::kRandom;
  agents[4].waypoints = {{-1.5, 3.5}, {2, 0.5}, {-5, 0.5}, {5, 3.5}};
  CrowdSim sim(agents, person, vehicle, 42);
  double worst_overlap = 0;
  double travelled = 0;
  for (int k = 0; k < 1200; ++k) {  // 60 s
    const auto before = sim.states();
    sim.Step({});
    for (size_t i = 0; i < agents.size(); ++i) {
      EXPECT_TRUE(person->Walkable(sim.states()[i].position_W)) << agents[i].name << " at " << k;
      travelled += (sim.states()[i].position_W - before[i].position_W).norm();
      for (size_t j = i + 1; j < agents.size(); ++j)
        worst_overlap = std::max(
            worst_overlap, 0.5 - (sim.states()[i].position_W - sim.states()[j].position_W).norm());
    }
  }
  EXPECT_LE(worst_overlap, 0.05);
  EXPECT_GT(travelled, 5 * 30.0);  // everyone keeps walking (5 agents, > 30 m each on average)
}

std::shared_ptr<const WalkableGrid> RoomsFor(double radius) {
  return std::make_shared<const WalkableGrid>(TwoRoomsGrid(), radius, Eigen::Vector2d(-5, 1));
}

TEST(CrowdSimTest, AvoidAgentsKeepTheirClearanceFromAStandingRobot) {
  // four walkers patrolling straight through where the robot stands, in the right room
  std::vector<AgentConfig> agents = {
      Walker("a", {{1, 2}, {5.5, 2}}), Walker("b", {{5.5, 2.1}, {1, 1.9}}),
      Walker("c", {{3, 0.4}, {3.2, 3.6}}), Walker("d", {{3.3, 3.6}, {2.9, 0.4}})};
  for (AgentConfig& a : agents) {
    a.route = AgentRoute::kPingPong;
    a.clearance_m = 0.6;
  }
  CrowdSim sim(agents, RoomsFor(0.3), RoomsFor(0.7), 3);
  CrowdRobot robot;
  robot.position_W = {3.1, 2.0};
  robot.radius_m = 0.4;
  double least_gap = 1e9;
  for (int k = 0; k < 1200; ++k) {
    sim.Step({robot});
    for (const CrowdAgentState& s : sim.states())
      least_gap = std::min(least_gap, (s.position_W - robot.position_W).norm() - 0.4 - 0.25);
  }
  EXPECT_GE(least_gap, 0.6 - 0.01);
  // `ignore` walkers do not plan or steer round the robot, but never walk into its contact
  // disc (robot radius + their reach 0.3 m + 0.02 m)
  for (AgentConfig& a : agents) a.behaviour = AgentBehaviour::kIgnore;
  CrowdSim careless(agents, RoomsFor(0.3), RoomsFor(0.7), 3);
  least_gap = 1e9;
  for (int k = 0; k < 400; ++k) {
    careless.Step({robot});
    for (const CrowdAgentState& s : careless.states())
      least_gap = std::min(least_gap, (s.position_W - robot.position_W).norm() - 0.4 - 0.3);
  }
  EXPECT_GE(least_gap, 0.02 - 1e-9);
  // with robot_contact (a preset's npcs.contact: true) they go straight through it
  for (AgentConfig& a : agents) a.robot_contact = true;
  CrowdSim pushing(agents, RoomsFor(0.3), RoomsFor(0.7), 3);
  least_gap = 1e9;
  for (int k = 0; k < 400; ++k) {
    pushing.Step({robot});
    for (const CrowdAgentState& s : pushing.states())
      least_gap = std::min(least_gap, (s.position_W - robot.position_W).norm() - 0.4 - 0.25);
  }
  EXPECT_LT(least_gap, 0.0);
}

TEST(CrowdSimTest, AgentsYieldToARobotThatWalksIntoThem) {
  // a walker paused at its waypoint in the middle of the right room, and a robot (0.4 m disc)
  // walking straight at it at 0.5 m/s: the walker steps away (a "yield" decision) and the
  // robot's disc never reaches the walker's reach by more than the robot's own step
  // (an `ignore` walker: an `avoid` one steps aside before, by ORCA; and a robot whose motion
  // the crowd does not see coming, velocity 0: else the walker gives way before, below)
  AgentConfig a = Walker("idle", {{3, 2}, {3.5, 2}});
  a.behaviour = AgentBehaviour::kIgnore;
  a.pause_sec = 60;  // stands at its goal
  a.route = AgentRoute::kOnce;
  for (const bool contact : {false, true}) {
    a.robot_contact = contact;
    CrowdSim sim({a}, RoomsFor(0.3), RoomsFor(0.7), 3);
    for (int k = 0; k < 40; ++k) sim.Step({});  // reaches (3.5, 2) and pauses there
    CrowdRobot robot;
    robot.radius_m = 0.4;
    double least = 1e9;
    bool yielded = false;
    const double t0 = sim.time_sec();
    for (int k = 0; k < 100; ++k) {  // 5 s: the robot walks from x = 1.2 to 3.7
      robot.position_W = {1.2 + 0.5 * (sim.time_sec() - t0), 2.0};
      sim.Step({robot});
      least = std::min(least, (sim.states()[0].position_W - robot.position_W).norm());
      for (const CrowdDecision& d : sim.TakeDecisions()) yielded = yielded || d.what == "yield";
    }
    if (!contact) {
      EXPECT_TRUE(yielded);
      EXPECT_GE(least, 0.4 + 0.3 + 0.02 - 0.5 * sim.dt() - 1e-9);
    } else {
      // agents that may push stay where they are: the robot walks into (through) them
      EXPECT_FALSE(yielded);
      EXPECT_LT(least, 0.4 + 0.25);
    }
  }
}

TEST(CrowdSimTest, APersonInARobotsWayWalksOutOfItBeforeTheRobotArrives) {
  // a walker standing in the right room on the line a robot drives (east along y = 2 through
  // the door at 0.5 m/s): it gives way (leaves the robot's swept corridor) before the robot
  // reaches it, instead of yielding ahead of it; with robot_contact it stays
  AgentConfig a = Walker("idle", {{2.5, 2.0}, {2.0, 2.0}});
  a.behaviour = AgentBehaviour::kIgnore;
  a.route = AgentRoute::kOnce;
  a.pause_sec = 60;
  for (const bool contact : {false, true}) {
    a.robot_contact = contact;
    CrowdSim sim({a}, RoomsFor(0.3), RoomsFor(0.7), 3);
    for (int k = 0; k < 40; ++k) sim.Step({});  // at (2, 2), paused
    sim.TakeDecisions();
    CrowdRobot robot;
    robot.radius_m = 0.4;
    robot.velocity_W = {0.5, 0};
    bool gave_way = false;
    double least = 1e9, lateral_at_pass = 0;
    const double t0 = sim.time_sec();
    for (int k = 0; k < 240; ++k) {  // 12 s: from x = -3 to x = 3
      robot.position_W = {-3.0 + 0.5 * (sim.time_sec() - t0), 2.0};
      sim.Step({robot});
      const Eigen::Vector2d p = sim.states()[0].position_W;
      least = std::min(least, (p - robot.position_W).norm());
      if (std::abs(robot.position_W.x() - p.x()) < 0.05) lateral_at_pass = std::abs(p.y() - 2.0);
      for (const CrowdDecision& d : sim.TakeDecisions())
        gave_way = gave_way || d.what == "give_way";
    }
    if (!contact) {
      EXPECT_TRUE(gave_way);
      EXPECT_GE(least, 0.4 + 0.3 + 0.02);            // never in its contact disc
      EXPECT_GE(lateral_at_pass, 0.4 + 0.3 + 0.02);  // beside the robot as it passed
    } else {
      EXPECT_FALSE(gave_way);
      EXPECT_LT(least, 0.4);
    }
  }
}

OccupancyGrid OpenHallGrid();

TEST(CrowdSimTest, AForkliftStopsWithItsForksClearOfARobotInItsLane) {
  // a forklift driving east along y = 0 in an open hall towards a robot standing in its lane:
  // it stops before its reach (1.95 m: the fork tips) meets the robot's disc; with
  // robot_contact it brakes at its own rate (ORCA on its 1.2 m disc) and gets closer
  const auto hall =
      std::make_shared<const WalkableGrid>(OpenHallGrid(), 0.7, Eigen::Vector2d(0, 0));
  AgentConfig f;
  f.name = "lift";
  f.kind = AgentKind::kForklift;
  f.motion = AgentMotion::kCrowd;
  f.waypoints = {{-6, 0}, {6, 0}};
  f.route = AgentRoute::kOnce;
  f.speed_m_s = 2.0;
  CrowdRobot robot;
  robot.position_W = {2, 0};
  robot.radius_m = 0.45;
  double gap[2] = {0, 0};
  for (const bool contact : {false, true}) {
    f.robot_contact = contact;
    CrowdSim sim({f}, hall, hall, 1);
    double least = 1e9;
    for (int k = 0; k < 400; ++k) {  // 20 s
      sim.Step({robot});
      least = std::min(least, (sim.states()[0].position_W - robot.position_W).norm());
    }
    gap[contact] = least - 0.45 - 1.95;
  }
  EXPECT_GE(gap[0], 0.0);
  EXPECT_LT(gap[1], gap[0] - 0.3);
}

TEST(CrowdSimTest, CrowdSitesSayWhereVehiclesMayDrive) {
  CrowdSites sites;
  sites.areas.push_back({"room", {0, 0}, {4, 3}, false});
  EXPECT_FALSE(sites.any_drivable());
  EXPECT_FALSE(sites.Drivable({1, 1}));
  sites.areas.push_back({"zone", {10, 0}, {20, 5}, true});
  sites.lanes.push_back({"aisle", {{0, 10}, {10, 10}}, true});
  EXPECT_TRUE(sites.any_drivable());
  EXPECT_FALSE(sites.Drivable({1, 1}));
  EXPECT_TRUE(sites.Drivable({15, 2.5}));
  EXPECT_TRUE(sites.Drivable({5, 10.8}, 1.0));
  EXPECT_FALSE(sites.Drivable({5, 11.2}, 1.0));
}

TEST(CrowdSimTest, BlockAgentsStepIntoTheRobotsPath) {
  AgentConfig a = Walker("blocker", {{-5, 3.5}, {-4, 3.5}});
  a.behaviour = AgentBehaviour::kBlock;
  CrowdSim sim({a}, RoomsFor(0.3), RoomsFor(0.7), 5);
  // the robot drives east along y = 1 at 0.3 m/s from x = -5.5
  CrowdRobot robot;
  robot.radius_m = 0.4;
  robot.velocity_W = {0.3, 0};
  bool in_path = false;
  for (int k = 0; k < 400 && !in_path; ++k) {  // 20 s
    robot.position_W = {-5.5 + 0.3 * sim.time_sec(), 1.0};
    sim.Step({robot});
    const Eigen::Vector2d p = sim.states()[0].position_W;
    // within the robot's swept corridor (its width plus the agent's), ahead of it, < 1.5 m away
    in_path = std::abs(p.y() - 1.0) < 0.4 + 0.25 && p.x() > robot.position_W.x() &&
              p.x() - robot.position_W.x() < 1.5;
  }
  EXPECT_TRUE(in_path);
  // an `avoid` agent with the same goals never does
  a.behaviour = AgentBehaviour::kAvoid;
  a.waypoints = {{-5, 3.5}, {-1, 3.5}};
  CrowdSim calm({a}, RoomsFor(0.3), RoomsFor(0.7), 5);
  for (int k = 0; k < 400; ++k) {
    robot.position_W = {-5.5 + 0.3 * calm.time_sec(), 1.0};
    calm.Step({robot});
    EXPECT_GT(std::abs(calm.states()[0].position_W.y() - 1.0), 0.65);
  }
}

TEST(CrowdSimTest, BlockAgentsStandTheirGroundInTheRobotsPathAndStepInFrontWhenItTurns) {
  AgentConfig a = Walker("blocker", {{-3, 1.0}, {-2, 1.0}});
  a.behaviour = AgentBehaviour::kBlock;
  CrowdSim sim({a}, RoomsFor(0.3), RoomsFor(0.7), 5);
  // the robot stands at (-5.5, 1) facing east: the blocker walks to its block point and holds
  CrowdRobot robot;
  robot.radius_m = 0.4;
  robot.position_W = {-5.5, 1.0};
  bool held = false;
  for (int k = 0; k < 200 && !held; ++k) {
    sim.Step({robot});
    for (const CrowdDecision& d : sim.TakeDecisions()) held = held || d.what == "hold";
  }
  ASSERT_TRUE(held);
  const Eigen::Vector2d hold_at = sim.states()[0].position_W;
  EXPECT_GT(hold_at.x(), robot.position_W.x());
  EXPECT_LE(std::abs(hold_at.y() - 1.0), 0.4 + 0.25);
  // the robot drives at it (0.3 m/s east): the blocker does not give way, so the robot's disc
  // reaches its disc (the robot walks into a standing person)
  robot.velocity_W = {0.3, 0};
  const double t0 = sim.time_sec();
  double least_gap = 1e9;
  while (robot.position_W.x() < hold_at.x() - 0.3) {  // until its centre is 0.3 m short of it
    robot.position_W = {-5.5 + 0.3 * (sim.time_sec() - t0), 1.0};
    sim.Step({robot});
    ASSERT_EQ(sim.states()[0].position_W, hold_at) << "at t = " << sim.time_sec();
    least_gap =
        std::min(least_gap, (sim.states()[0].position_W - robot.position_W).norm() - 0.4 - 0.25);
  }
  EXPECT_LT(least_gap, 0.0);
  // the robot backs off and turns north: the blocker leaves its place and steps in front of it
  // again within 4 s
  robot.position_W = {-5.5, 1.0};
  robot.velocity_W = {0, 0.3};
  const double t1 = sim.time_sec();
  bool in_path = false;
  for (int k = 0; k < 80 && !in_path; ++k) {
    robot.position_W = {-5.5, 1.0 + 0.3 * (sim.time_sec() - t1)};
    sim.Step({robot});
    const Eigen::Vector2d p = sim.states()[0].position_W;
    in_path = std::abs(p.x() - robot.position_W.x()) <= 0.4 + 0.25 &&
              p.y() > robot.position_W.y() && p.y() - robot.position_W.y() < 1.65;
  }
  EXPECT_TRUE(in_path);
}

// a 16 x 16 m hall with walls round it
OccupancyGrid OpenHallGrid() {
  OccupancyGrid g;
  g.min_W = {-8.2, -8.2};
  g.cell_m = 0.1;
  g.nx = 164;
  g.ny = 164;
  g.blocked.assign(static_cast<size_t>(g.nx) * g.ny, 0);
  for (int iy = 0; iy < g.ny; ++iy)
    for (int ix = 0; ix < g.nx; ++ix) {
      const double x = g.min_W.x() + (ix + 0.5) * g.cell_m, y = g.min_W.y() + (iy + 0.5) * g.cell_m;
      g.blocked[iy * g.nx + ix] = std::abs(x) > 8.0 || std::abs(y) > 8.0;
    }
  return g;
}

TEST(CrowdSimTest, VehicleWheelbaseIsTheBodysAxleSpacing) {
  // the bicycle model steers the body that is drawn: its wheelbase is the distance between
  // the body's front and rear axles (compose/agent_bodies.cc places the wheels there)
  for (AgentKind kind : {AgentKind::kForklift, AgentKind::kCart}) {
    double front = -1e9, rear = 1e9;
    for (const AgentWheel& w : AgentWheels(kind)) {
      front = std::max(front, w.centre.x());
      rear = std::min(rear, w.centre.x());
    }
    EXPECT_NEAR(KindModel(kind).wheelbase_m, front - rear, 1e-12);
    EXPECT_NEAR(AgentWheelbase(kind), front - rear, 1e-12);
  }
  EXPECT_NEAR(KindModel(AgentKind::kForklift).wheelbase_m, 1.1, 1e-12);
  EXPECT_NEAR(KindModel(AgentKind::kCart).wheelbase_m, 0.8, 1e-12);
  EXPECT_EQ(KindModel(AgentKind::kPerson).wheelbase_m, 0.0);
}

TEST(CrowdSimTest, AForkliftsWheelsSteerAsItsBicycleModelTurns) {
  // a forklift patrolling a square in an open hall: in its corners the crowd's bicycle model
  // turns on curvature k (measured from its poses) with steering atan(L k); the rear wheels of
  // its body, animated from the same poses, must show that angle (negated: rear steering)
  const auto hall =
      std::make_shared<const WalkableGrid>(OpenHallGrid(), 0.7, Eigen::Vector2d(0, 0));
  AgentConfig f;
  f.name = "lift";
  f.kind = AgentKind::kForklift;
  f.motion = AgentMotion::kCrowd;
  f.waypoints = {{-4, -4}, {4, -4}, {4, 4}, {-4, 4}};
  f.route = AgentRoute::kLoop;
  f.speed_m_s = 1.5;
  f.pause_sec = 0;
  CrowdSim sim({f}, hall, hall, 1);
  std::vector<CrowdAgentState> states = {sim.states()[0]};
  for (int k = 0; k < 800; ++k) {  // 40 s
    sim.Step({});
    states.push_back(sim.states()[0]);
  }
  const double dt = sim.dt();
  // the crowd's poses, linear between its steps
  const auto X_WA = [&](double t) {
    const double u = std::clamp(t / dt, 0.0, static_cast<double>(states.size() - 1));
    const size_t k = std::min(static_cast<size_t>(u), states.size() - 2);
    const double a = u - static_cast<double>(k);
    const CrowdAgentState &s0 = states[k], &s1 = states[k + 1];
    Pose X = Pose::Identity();
    const Eigen::Vector2d p = (1 - a) * s0.position_W + a * s1.position_W;
    const double yaw = s0.yaw + a * std::remainder(s1.yaw - s0.yaw, 2 * M_PI);
    X.translation() = Eigen::Vector3d(p.x(), p.y(), 0);
    X.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    return X;
  };
  AgentAnimator animator(AgentKind::kForklift, 1.75, X_WA);
  const std::vector<AgentWheel> wheels = AgentWheels(AgentKind::kForklift);
  const AgentWheel* rear = nullptr;
  for (const AgentWheel& w : wheels)
    if (w.steer == -1) rear = &w;
  ASSERT_NE(rear, nullptr);
  const double L = KindModel(AgentKind::kForklift).wheelbase_m;
  int compared = 0;
  double worst = 0;
  // steady turns: the curvature over each of the last four 0.25 s windows agrees within 2 %
  const int w = 5;
  for (size_t k = 4 * w; k + 1 < states.size(); ++k) {
    double kappa[4];
    bool steady = true;
    for (int j = 0; j < 4; ++j) {
      const CrowdAgentState &a = states[k - (j + 1) * w], &b = states[k - j * w];
      const double ds = (b.position_W - a.position_W).norm();
      steady = steady && ds > 0.2;
      kappa[j] = steady ? std::remainder(b.yaw - a.yaw, 2 * M_PI) / ds : 0;
    }
    for (int j = 1; j < 4 && steady; ++j)
      steady = std::abs(kappa[j] - kappa[0]) <= 0.02 * std::abs(kappa[0]);
    if (!steady || std::abs(kappa[0]) < 0.2) continue;
    const double want = -std::atan(L * kappa[0]);
    const double got = animator.SteerAngle(static_cast<double>(k) * dt, *rear);
    worst = std::max(worst, std::abs(got - want));
    ++compared;
  }
  EXPECT_GE(compared, 5);  // steady stretches of its corners
  EXPECT_LT(worst, 0.01);  // rad
}

// every agent's pose over 30 s of a mixed crowd (random goals) as raw bits
std::vector<uint64_t> CrowdBits(uint64_t seed) {
  std::vector<AgentConfig> agents;
  for (int i = 0; i < 6; ++i) {
    AgentConfig a =
        Walker("w" + std::to_string(i), {{-5 + i, 0.6}, {4, 3.4}, {-4, 3.4}, {5, 0.6}, {-2, 2}});
    a.goals = AgentGoals::kRandom;
    agents.push_back(a);
  }
  CrowdSim sim(agents, RoomsFor(0.3), RoomsFor(0.7), seed);
  std::vector<uint64_t> bits;
  for (int k = 0; k < 600; ++k) {
    sim.Step({});
    for (const CrowdAgentState& s : sim.states())
      for (double v : {s.position_W.x(), s.position_W.y(), s.yaw}) {
        uint64_t b = 0;
        std::memcpy(&b, &v, sizeof b);
        bits.push_back(b);
      }
  }
  return bits;
}

TEST(CrowdSimTest, SameSeedGivesBitIdenticalTrajectories) {
  EXPECT_EQ(CrowdBits(9), CrowdBits(9));
  EXPECT_NE(CrowdBits(9), CrowdBits(10));
}

}  // namespace
}  // namespace penumbra
