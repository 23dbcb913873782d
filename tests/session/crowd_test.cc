// the NPC crowd in the bundled house and warehouse: presets place crowds from the
// generated environments' rooms and lanes on the walkable map, and the crowd model alone (no
// physics, no rendering) keeps every agent on its region, apart from the others and clear of a
// standing robot for 60 s; a session's crowd trajectories are bit-identical for a seed
// (tests/replay/crowd_replay_test.cc: replay reproduces them).

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <filesystem>
#include <fstream>

#include "common/temp_dir.h"
#include "penumbra/core/error.h"
#include "penumbra/effects/crowd_sim.h"
#include "penumbra/session/session.h"
#include "penumbra/world/adversity_preset.h"

namespace penumbra {
namespace {

std::string CrowdWorldPath(const std::string& rel) {
  return (std::filesystem::path(PENUMBRA_SOURCE_DIR) / "worlds" / rel).string();
}

// a one-preset file with `npcs` as given
std::string CrowdPresetFile(const testing::TempDir& dir, const std::string& npcs) {
  const std::string path = (dir.path() / "crowd_preset.yaml").string();
  std::ofstream(path) << "presets:\n  crowd:\n    npcs: " << npcs << "\n";
  return path;
}

// the session's crowd agents (motion: crowd), in the stage's order
std::vector<AgentConfig> CrowdAgentsOf(const Session& session) {
  std::vector<AgentConfig> crowd;
  for (const AgentConfig& a : session.effects().agents())
    if (a.motion == AgentMotion::kCrowd) crowd.push_back(a);
  return crowd;
}

// every robot of `world` standing at its start pose, as the crowd sees it (a 0.45 m disc)
std::vector<CrowdRobot> StandingRobotsOf(const WorldConfig& world) {
  std::vector<CrowdRobot> robots;
  for (const ModelConfig& m : world.models)
    if (m.is_robot) {
      CrowdRobot r;
      r.position_W = m.pose.xyz.head<2>();
      r.radius_m = 0.45;
      r.yaw = m.pose.rpy_deg.z() * M_PI / 180;
      robots.push_back(r);
    }
  return robots;
}

struct CrowdRunStats {
  int steps = 0;
  int off_region = 0;
  double worst_overlap_m = 0;
  double least_robot_gap_m = 1e9;  // avoid agents: gap between the discs minus clearance
  double travelled_m = 0;
  double vehicle_travelled_m = 0;
  size_t agents = 0, vehicles = 0;
};

// the session's crowd stepped alone for `seconds` beside its standing robots
CrowdRunStats RunCrowdAlone(const Session& session, double seconds) {
  const std::vector<AgentConfig> crowd = CrowdAgentsOf(session);
  const std::shared_ptr<const NpcMap> map = session.effects().npc_map();
  CrowdRunStats st;
  if (!map) return st;
  CrowdSim sim(crowd, map->person(), map->vehicle(), session.world().seed);
  const std::vector<CrowdRobot> robots = StandingRobotsOf(session.world());
  st.agents = crowd.size();
  for (const AgentConfig& a : crowd) st.vehicles += IsVehicle(a.kind);
  const int steps = static_cast<int>(seconds / sim.dt());
  for (int k = 0; k < steps; ++k) {
    const std::vector<CrowdAgentState> before = sim.states();
    sim.Step(robots);
    ++st.steps;
    const std::vector<CrowdAgentState>& s = sim.states();
    for (size_t i = 0; i < s.size(); ++i) {
      st.off_region += !sim.region(i).Walkable(s[i].position_W);
      st.travelled_m += (s[i].position_W - before[i].position_W).norm();
      if (IsVehicle(crowd[i].kind))
        st.vehicle_travelled_m += (s[i].position_W - before[i].position_W).norm();
      const double ri = KindModel(crowd[i].kind).disc_radius_m;
      for (size_t j = i + 1; j < s.size(); ++j) {
        const double rj = KindModel(crowd[j].kind).disc_radius_m;
        st.worst_overlap_m =
            std::max(st.worst_overlap_m, ri + rj - (s[i].position_W - s[j].position_W).norm());
      }
      if (crowd[i].behaviour == AgentBehaviour::kAvoid)
        for (const CrowdRobot& r : robots)
          st.least_robot_gap_m =
              std::min(st.least_robot_gap_m, (s[i].position_W - r.position_W).norm() - ri -
                                                 r.radius_m - crowd[i].clearance_m);
    }
  }
  return st;
}

SessionOptions CrowdSessionOptions(const std::string& preset) {
  SessionOptions o;
  o.build_renderer = false;
  o.add_controllers = false;
  o.adversity = preset;
  return o;
}

TEST(CrowdTest, HouseCrowdStaysWalkableApartAndClearOfTheRobotFor60s) {
  const testing::TempDir dir;
  const Session session(LoadWorldFile(CrowdWorldPath("house.yaml")),
                        CrowdSessionOptions(CrowdPresetFile(dir, "{people: 8, vehicles: 1}")));
  const CrowdRunStats st = RunCrowdAlone(session, 60.0);
  // no forklift fits the house's doors and hallway: the preset leaves it out
  EXPECT_EQ(st.agents, 8u);
  EXPECT_EQ(st.vehicles, 0u);
  EXPECT_EQ(st.steps, 1200);
  EXPECT_EQ(st.off_region, 0);
  EXPECT_LE(st.worst_overlap_m, 0.05);
  EXPECT_GE(st.least_robot_gap_m, -0.01);
  EXPECT_GT(st.travelled_m, 8 * 20.0);  // people keep walking: > 20 m each on average
  // (the robot stands in the hallway by the living room's door: a person whose room it cuts
  // off waits; the others route round it)
  // people start apart (discs 0.3 m apart) and 1.5 m from the robot
  const auto& agents = session.effects().agents();
  for (size_t i = 0; i < agents.size(); ++i) {
    EXPECT_GE((agents[i].waypoints[0] - Eigen::Vector2d(-2.0, -0.75)).norm(), 1.5);
    for (size_t j = i + 1; j < agents.size(); ++j)
      EXPECT_GE((agents[i].waypoints[0] - agents[j].waypoints[0]).norm(), 0.8 - 1e-9);
  }
}

TEST(CrowdTest, WarehouseForkliftsDriveTheAisleAmongPeopleFor60s) {
  const testing::TempDir dir;
  const Session session(LoadWorldFile(CrowdWorldPath("warehouse.yaml")),
                        CrowdSessionOptions(CrowdPresetFile(dir, "{people: 6, vehicles: 1}")));
  const CrowdRunStats st = RunCrowdAlone(session, 60.0);
  EXPECT_EQ(st.agents, 7u);
  EXPECT_EQ(st.vehicles, 1u);
  EXPECT_GT(st.vehicle_travelled_m, 20.0);  // the forklift drives its lane
  EXPECT_EQ(st.off_region, 0);
  EXPECT_LE(st.worst_overlap_m, 0.05);
  EXPECT_GE(st.least_robot_gap_m, -0.01);
  EXPECT_GT(st.travelled_m, 7 * 15.0);
  // the forklifts' lanes lie on the walkway of the aisle (the warehouse's lane)
  for (const AgentConfig& a : session.effects().agents()) {
    if (a.kind == AgentKind::kForklift) {
      EXPECT_GE(a.waypoints.size(), 2u);
    }
  }
}

TEST(CrowdTest, PresetPeopleAreAsTallAsThePresetDrewThem) {
  // the preset draws each person's height in [1.55, 1.95] m from the seed; the walker's body
  // (compose/agent_bodies.cc: head radius 0.063 H) must be built at that height
  const testing::TempDir dir;
  const Session session(LoadWorldFile(CrowdWorldPath("house.yaml")),
                        CrowdSessionOptions(CrowdPresetFile(dir, "{people: 6}")));
  int people = 0;
  double lo = 10, hi = 0;
  for (const AgentConfig& a : session.effects().agents()) {
    if (a.kind != AgentKind::kPerson) continue;
    ++people;
    EXPECT_TRUE(a.height_given) << a.name;
    EXPECT_GE(a.height_m, 1.55);
    EXPECT_LE(a.height_m, 1.95);
    lo = std::min(lo, a.height_m);
    hi = std::max(hi, a.height_m);
    const std::string head = "agents/" + a.name + "/head";
    int found = 0;
    for (const Geom& g : session.scene().geoms)
      if (g.name == head) {
        ++found;
        EXPECT_NEAR(g.size.x(), 0.063 * a.height_m, 1e-12) << a.name;
      }
    EXPECT_EQ(found, 1) << head;
  }
  EXPECT_EQ(people, 6);
  EXPECT_GT(hi - lo, 0.05);  // not one height for all
}

TEST(CrowdTest, BlockPeopleOfAPresetReachTheStandingRobotsPathInBothWorlds) {
  // `behaviour: block` in a preset: each person walks from where the preset placed it (>= 1.5 m
  // from the robot) into the robot's path: ahead of it along its heading, within its width
  // plus the person's, less than 2 m in front
  for (const std::string world_file : {"house.yaml", "warehouse.yaml"}) {
    const testing::TempDir dir;
    const Session session(
        LoadWorldFile(CrowdWorldPath(world_file)),
        CrowdSessionOptions(CrowdPresetFile(dir, "{people: 3, behaviour: block}")));
    const std::vector<AgentConfig> crowd = CrowdAgentsOf(session);
    ASSERT_EQ(crowd.size(), 3u) << world_file;
    const std::shared_ptr<const NpcMap> map = session.effects().npc_map();
    ASSERT_TRUE(map);
    CrowdSim sim(crowd, map->person(), map->vehicle(), session.world().seed);
    const std::vector<CrowdRobot> robots = StandingRobotsOf(session.world());
    ASSERT_FALSE(robots.empty());
    const CrowdRobot robot = robots.front();
    const Eigen::Vector2d heading(std::cos(robot.yaw), std::sin(robot.yaw));
    const Eigen::Vector2d left(-heading.y(), heading.x());
    const double person_r = KindModel(AgentKind::kPerson).disc_radius_m;
    std::vector<double> reached(crowd.size(), -1);
    for (int k = 0; k < 600; ++k) {  // 30 s
      sim.Step({robot});
      for (size_t i = 0; i < crowd.size(); ++i) {
        const Eigen::Vector2d d = sim.states()[i].position_W - robot.position_W;
        const double ahead = d.dot(heading), side = std::abs(d.dot(left));
        if (reached[i] < 0 && ahead > 0 && ahead < 2.0 && side < robot.radius_m + person_r)
          reached[i] = sim.time_sec();
        EXPECT_TRUE(sim.region(i).Walkable(sim.states()[i].position_W));
      }
    }
    for (size_t i = 0; i < crowd.size(); ++i) {
      EXPECT_GT((crowd[i].waypoints[0] - robot.position_W).norm(), 1.5);
      EXPECT_GE(reached[i], 0.0) << world_file << ": " << crowd[i].name << " never stood in the "
                                 << "robot's path";
    }
  }
}

// the first time (s) each agent of `sim` stands in `robot`'s path (ahead of it along `heading`
// by less than 2 m, within the discs' radii sideways) over 8 s of crowd steps; -1 when never
std::vector<double> TimesInRobotsPath(CrowdSim* sim, const CrowdRobot& robot,
                                      const Eigen::Vector2d& heading) {
  const Eigen::Vector2d left(-heading.y(), heading.x());
  const double person_r = KindModel(AgentKind::kPerson).disc_radius_m;
  std::vector<double> reached(sim->states().size(), -1);
  for (int k = 0; k < 160; ++k) {  // 8 s
    sim->Step({robot});
    for (size_t i = 0; i < reached.size(); ++i) {
      const Eigen::Vector2d d = sim->states()[i].position_W - robot.position_W;
      const double ahead = d.dot(heading), side = std::abs(d.dot(left));
      if (reached[i] < 0 && ahead > 0 && ahead < 2.0 && side < robot.radius_m + person_r)
        reached[i] = sim->time_sec();
    }
  }
  return reached;
}

TEST(CrowdTest, BlockPeopleOfAPresetStartInFrontOfTheRobotAndReachItsPathWithin8s) {
  // `behaviour: block` people start where the robot is about to go (effects_stage.h "npcs"):
  // each on a walkable cell 2-6 m from the robot within 60 deg of its start heading, apart
  // from each other, and each stands in the robot's path (as above) within 8 s. the same
  // preset with `avoid` keeps its places at the points of interest and lanes
  for (const std::string world_file : {"house.yaml", "warehouse.yaml", "default.yaml"}) {
    for (const std::string behaviour : {"block", "avoid"}) {
      const testing::TempDir dir;
      const Session session(LoadWorldFile(CrowdWorldPath(world_file)),
                            CrowdSessionOptions(CrowdPresetFile(
                                dir, "{people: 4, speed_m_s: 0.8, behaviour: " + behaviour + "}")));
      const std::vector<AgentConfig> crowd = CrowdAgentsOf(session);
      ASSERT_EQ(crowd.size(), 4u) << world_file << " " << behaviour;
      const std::shared_ptr<const NpcMap> map = session.effects().npc_map();
      ASSERT_TRUE(map);
      const std::vector<CrowdRobot> robots = StandingRobotsOf(session.world());
      ASSERT_FALSE(robots.empty());
      const CrowdRobot robot = robots.front();
      const Eigen::Vector2d heading(std::cos(robot.yaw), std::sin(robot.yaw));
      int in_front = 0;
      for (size_t i = 0; i < crowd.size(); ++i) {
        const Eigen::Vector2d d = crowd[i].waypoints[0] - robot.position_W;
        const bool front = d.norm() >= 2.0 && d.norm() <= 6.0 &&
                           d.dot(heading) >= d.norm() * std::cos(M_PI / 3) - 1e-9;
        in_front += front;
        if (behaviour == "block") {
          EXPECT_TRUE(front) << world_file << ": " << crowd[i].name << " starts at "
                             << crowd[i].waypoints[0].transpose() << ", not 2-6 m ahead";
          EXPECT_TRUE(map->person()->Walkable(crowd[i].waypoints[0])) << crowd[i].name;
          for (size_t j = 0; j < i; ++j)
            EXPECT_GT((crowd[i].waypoints[0] - crowd[j].waypoints[0]).norm(), 0.8);
        }
      }
      if (behaviour == "avoid") {
        // points of interest and lanes: not all of them ahead of the robot
        EXPECT_LT(in_front, 4) << world_file;
        continue;
      }
      CrowdSim sim(crowd, map->person(), map->vehicle(), session.world().seed);
      const std::vector<double> reached = TimesInRobotsPath(&sim, robot, heading);
      for (size_t i = 0; i < crowd.size(); ++i)
        EXPECT_GE(reached[i], 0.0)
            << world_file << ": " << crowd[i].name << " not in the robot's path within 8 s";
    }
  }
}

// distance from p to the polyline `route`, m
double DistanceToRoute(const std::vector<Eigen::Vector2d>& route, const Eigen::Vector2d& p) {
  double best = 1e9;
  for (size_t k = 1; k < route.size(); ++k) {
    const Eigen::Vector2d ab = route[k] - route[k - 1];
    const double t = ab.squaredNorm() > 0
                         ? std::clamp((p - route[k - 1]).dot(ab) / ab.squaredNorm(), 0.0, 1.0)
                         : 0.0;
    best = std::min(best, (p - route[k - 1] - t * ab).norm());
  }
  return best;
}

TEST(CrowdTest, BlockPeopleWithAGoalBehindTheRobotStartOnItsRouteAndReachItsPathWithin8s) {
  // npcs.block_goal (effects_stage.h "npcs"): with the goal behind the robot (the room of
  // default.yaml and rover.yaml), block people start within 1 m of the robot's route to it
  // (A* on the people's walkable cells), 1.5-7 m from the robot, behind its start heading; once the
  // robot has turned to its route, each stands in its path within 8 s. without the goal the same
  // preset puts them ahead
  for (const std::string world_file : {"rover.yaml", "default.yaml"}) {
    const WorldConfig world = LoadWorldFile(CrowdWorldPath(world_file));
    const std::vector<CrowdRobot> robots = StandingRobotsOf(world);
    ASSERT_FALSE(robots.empty()) << world_file;
    const Eigen::Vector2d start = robots.front().position_W;
    const Eigen::Vector2d heading(std::cos(robots.front().yaw), std::sin(robots.front().yaw));
    // the nav benchmark's rover episode behind_start (benchmarks/nav.yaml): 2.8 m away,
    // 107 deg off the start heading
    const Eigen::Vector2d goal(-2.5, 0.1);
    const testing::TempDir dir;
    const Session session(
        world, CrowdSessionOptions(CrowdPresetFile(dir,
                                                   "{people: 3, speed_m_s: 0.8, behaviour: block, "
                                                   "block_goal: [-2.5, 0.1]}")));
    const std::vector<AgentConfig> crowd = CrowdAgentsOf(session);
    ASSERT_EQ(crowd.size(), 3u) << world_file;
    const std::shared_ptr<const NpcMap> map = session.effects().npc_map();
    ASSERT_TRUE(map);
    const std::optional<std::vector<Eigen::Vector2d>> route = map->person()->Plan(start, goal);
    ASSERT_TRUE(route && route->size() >= 2) << world_file;
    for (const AgentConfig& a : crowd) {
      const Eigen::Vector2d d = a.waypoints[0] - start;
      EXPECT_LE(DistanceToRoute(*route, a.waypoints[0]), 1.0 + 1e-6)
          << world_file << ": " << a.name << " starts at " << a.waypoints[0].transpose();
      EXPECT_GE(d.norm(), 1.5) << a.name;
      EXPECT_LE(d.norm(), 7.0) << a.name;
      EXPECT_LT(d.dot(heading), 0.0) << world_file << ": " << a.name << " starts ahead";
      EXPECT_TRUE(map->person()->Walkable(a.waypoints[0])) << a.name;
    }
    // the robot turned to its route's first leg
    CrowdRobot robot;
    robot.position_W = start;
    const Eigen::Vector2d leg = ((*route)[1] - (*route)[0]).normalized();
    robot.yaw = std::atan2(leg.y(), leg.x());
    robot.radius_m = 0.45;
    CrowdSim sim(crowd, map->person(), map->vehicle(), session.world().seed);
    const std::vector<double> reached = TimesInRobotsPath(&sim, robot, leg);
    for (size_t i = 0; i < crowd.size(); ++i)
      EXPECT_GE(reached[i], 0.0) << world_file << ": " << crowd[i].name
                                 << " not in the robot's path within 8 s";
  }
}

TEST(CrowdTest, AdversityPresetFileTextReadsBackTheSamePresetWithItsBlockGoal) {
  // what penumbra benchmark writes for a nav episode (campaign/nav_job.h)
  const testing::TempDir dir;
  AdversityPreset p = LoadAdversityPreset(
      CrowdPresetFile(dir,
                      "{people: 2, speed_m_s: 0.7, behaviour: block, block_goal: [-2.5, "
                      "0.1]}"));
  ASSERT_TRUE(p.npc_block_goal);
  EXPECT_EQ(*p.npc_block_goal, Eigen::Vector2d(-2.5, 0.1));
  p.npc_block_goal = Eigen::Vector2d(0.1 + 0.2, -1.0 / 3);
  const std::string path = (dir.path() / "again.yaml").string();
  std::ofstream(path) << AdversityPresetFileText(p);
  const AdversityPreset q = LoadAdversityPreset(path + "#crowd");
  ASSERT_TRUE(q.npc_block_goal);
  EXPECT_EQ(*q.npc_block_goal, *p.npc_block_goal);  // bit-exact
  EXPECT_EQ(q.npc_people, 2);
  EXPECT_EQ(q.npc_speed_m_s, 0.7);
  EXPECT_EQ(q.npc_behaviour, AgentBehaviour::kBlock);
  // a goal without block is refused
  EXPECT_THROW(LoadAdversityPreset(CrowdPresetFile(dir, "{people: 2, block_goal: [1, 2]}")),
               ConfigError);
}

// every agent body's mocap pose over `steps` physics steps of a session with a crowd
std::vector<double> CrowdTrajectory(uint64_t seed, int steps) {
  const testing::TempDir dir;
  WorldConfig world = LoadWorldFile(CrowdWorldPath("house.yaml"));
  world.seed = seed;
  SessionOptions o = CrowdSessionOptions(CrowdPresetFile(dir, "{people: 5}"));
  o.add_controllers = true;
  Session session(world, o);
  std::vector<double> out;
  for (int k = 0; k < steps; ++k) {
    session.sim().Step();
    const SimState s = session.sim().GetState();
    out.insert(out.end(), s.mocap_pos.begin(), s.mocap_pos.end());
    out.insert(out.end(), s.mocap_quat.begin(), s.mocap_quat.end());
  }
  return out;
}

TEST(CrowdTest, SameSeedGivesBitIdenticalCrowdTrajectories) {
  const std::vector<double> a = CrowdTrajectory(11, 1500), b = CrowdTrajectory(11, 1500);
  const std::vector<double> c = CrowdTrajectory(12, 1500);
  ASSERT_EQ(a.size(), b.size());
  ASSERT_FALSE(a.empty());
  bool same = true;
  for (size_t i = 0; i < a.size(); ++i)
    same = same && std::bit_cast<uint64_t>(a[i]) == std::bit_cast<uint64_t>(b[i]);
  EXPECT_TRUE(same);
  EXPECT_NE(a, c);  // another seed: another crowd
}

TEST(CrowdTest, AgentRootsMoveSmoothlyBetweenCrowdSteps) {
  // the crowd steps every 0.05 s and the physics every 0.002 s: between two crowd steps a
  // person's root moves on, at its walking speed (<= 1 m/s here), at every physics step; it
  // neither holds still for part of the crowd step nor jumps to catch up (the jump read as a
  // 5 m/s approach in the contacts metric)
  const testing::TempDir dir;
  SessionOptions o = CrowdSessionOptions(CrowdPresetFile(dir, "{people: 4, speed_m_s: 0.8}"));
  o.add_controllers = true;
  Session session(LoadWorldFile(CrowdWorldPath("house.yaml")), o);
  const std::vector<std::string> names = session.sim().MocapBodyNames();
  std::vector<size_t> roots;
  for (size_t i = 0; i < names.size(); ++i)
    if (names[i].rfind("agents/", 0) == 0 && names[i].find('/', 7) == std::string::npos)
      roots.push_back(i);
  ASSERT_EQ(roots.size(), 4u);
  const double dt = session.sim().timestep();
  std::vector<double> before;
  double fastest = 0, travelled = 0;
  int still = 0, moving = 0;
  for (int k = 0; k < 2500; ++k) {  // 5 s
    session.sim().Step();
    const std::vector<double> p = session.sim().GetState().mocap_pos;
    if (!before.empty())
      for (size_t r : roots) {
        const double d = std::hypot(p[3 * r] - before[3 * r], p[3 * r + 1] - before[3 * r + 1]);
        fastest = std::max(fastest, d / dt);
        travelled += d;
        (d == 0 ? still : moving) += 1;
      }
    before = p;
  }
  EXPECT_GT(travelled, 4 * 1.0);  // they walk
  EXPECT_LE(fastest, 1.0) << "a root moved " << fastest * dt << " m in one physics step";
  // a walking person holds still only where it pauses or waits: not half of every crowd step
  EXPECT_GT(moving, 3 * still);
}

}  // namespace
}  // namespace penumbra
