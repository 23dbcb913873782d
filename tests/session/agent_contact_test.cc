// adversity degrades the sensing, not the scene: under the bundled `major` preset the default
// room and the house keep their quadruped free for the whole run (the world's duration_sec,
// physics and controllers, no rendering): no contact force on the robot from an agent above
// the robot's weight, read from MuJoCo's contacts (WorldSnapshot::contacts) at every step.
// before agents kept out of robots, `major` sent a forklift across the default room into the
// quadruped at about 4.4 s and pinned it there.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "common/temp_dir.h"
#include "penumbra/compose/agent_bodies.h"
#include "penumbra/effects/crowd_sim.h"
#include "penumbra/physics/simulation.h"
#include "penumbra/session/session.h"

namespace penumbra {
namespace {

struct ContactStats {
  double robot_weight_N = 0;
  double worst_agent_force_N = 0;  // largest total normal force from agents at one step
  int steps_in_contact = 0;
  double nearest_agent_m = 1e9;  // plan distance agent root - robot root
  int steps = 0;
};

// the world's whole run, or its first `max_sec` seconds
ContactStats RunUnderPreset(const std::string& world_file, const std::string& preset,
                            double max_sec = 1e9, uint64_t seed = 0) {
  SessionOptions o;
  o.build_renderer = false;
  o.adversity = preset;
  WorldConfig world =
      LoadWorldFile((std::filesystem::path(PENUMBRA_SOURCE_DIR) / "worlds" / world_file).string());
  if (seed != 0) world.seed = seed;  // the NPCs' places and goals (0: the world's)
  Session session(world, o);
  Simulation& sim = session.sim();
  const ModelInfo& info = sim.model_info();
  const std::string robot = "go1/";
  std::vector<char> is_robot(info.body_names.size(), 0), is_agent(info.body_names.size(), 0);
  ContactStats st;
  int robot_root = -1;
  for (size_t b = 0; b < info.body_names.size(); ++b) {
    const std::string& n = info.body_names[b];
    is_robot[b] = n.rfind(robot, 0) == 0;
    if (is_robot[b]) {
      st.robot_weight_N += info.body_mass[b] * 9.81;
      if (robot_root < 0) robot_root = static_cast<int>(b);
    }
    for (const AgentConfig& a : session.effects().agents())
      is_agent[b] = is_agent[b] || IsAgentBodyOf(n, a.name);
  }
  std::vector<int> agent_roots;
  for (const AgentConfig& a : session.effects().agents())
    agent_roots.push_back(info.Find(ModelObject::kBody, AgentBodyName(a.name)));
  const int steps =
      static_cast<int>(std::min(session.world().duration_sec, max_sec) / sim.timestep());
  WorldSnapshot snap;
  for (int k = 0; k < steps; ++k) {
    sim.Step();
    sim.Snapshot(&snap, Simulation::SnapshotContent::kFull);
    double force = 0;
    for (const WorldSnapshot::Contact& c : snap.contacts) {
      const bool b1 = c.body1 >= 0 && static_cast<size_t>(c.body1) < is_robot.size();
      const bool b2 = c.body2 >= 0 && static_cast<size_t>(c.body2) < is_robot.size();
      if (!b1 || !b2) continue;
      if ((is_robot[c.body1] && is_agent[c.body2]) || (is_agent[c.body1] && is_robot[c.body2]))
        force += c.force_N.x();
    }
    st.worst_agent_force_N = std::max(st.worst_agent_force_N, force);
    st.steps_in_contact += force > 0;
    for (const int a : agent_roots)
      if (a >= 0)
        st.nearest_agent_m = std::min(
            st.nearest_agent_m,
            (snap.X_WB[a].translation().head<2>() - snap.X_WB[robot_root].translation().head<2>())
                .norm());
    ++st.steps;
  }
  std::printf(
      "%s under %s: robot weight %.1f N, largest force from agents %.1f N, %d steps in "
      "contact, nearest agent %.2f m\n",
      world_file.c_str(), preset.c_str(), st.robot_weight_N, st.worst_agent_force_N,
      st.steps_in_contact, st.nearest_agent_m);
  return st;
}

TEST(AgentContactTest, DefaultRoomUnderMajorKeepsTheRobotFreeForTheWholeRun) {
  // 20 s (the world's duration; the forklift used to hit at 4.4 s). the room is no place
  // for a vehicle: major's forklift is left out, its four people walk the room
  const ContactStats st = RunUnderPreset("default.yaml", "major");
  EXPECT_EQ(st.steps, 10000);
  EXPECT_GT(st.robot_weight_N, 50.0);
  EXPECT_LT(st.worst_agent_force_N, st.robot_weight_N)
      << st.steps_in_contact << " steps in contact with an agent";
  EXPECT_EQ(st.steps_in_contact, 0);
  // the people came near the robot: the test sees them pass it, not a crowd far away
  EXPECT_LT(st.nearest_agent_m, 2.0);
}

TEST(AgentContactTest, HouseUnderMajorKeepsTheRobotFreeForTheWholeRun) {
  // 28 s through doors and the hallway, where people get in the robot's way (give way, yield);
  // the world's seed and another (the people's places and goals)
  for (const uint64_t seed : {0, 3}) {
    const ContactStats st = RunUnderPreset("house.yaml", "major", 1e9, seed);
    EXPECT_EQ(st.steps, 14000);
    EXPECT_LT(st.worst_agent_force_N, st.robot_weight_N)
        << st.steps_in_contact << " steps in contact with an agent, seed " << seed;
    EXPECT_EQ(st.steps_in_contact, 0) << "seed " << seed;
    EXPECT_LT(st.nearest_agent_m, 2.0) << "seed " << seed;
  }
}

TEST(AgentContactTest, WarehouseForkliftsOnTheRobotsAisleKeepTheirForksOffIt) {
  // major's forklift drives the tour (the main aisle) that the quadruped walks, among the
  // world's own two forklifts and major's people; the first 24 s: the robot walks the aisle
  const ContactStats st = RunUnderPreset("warehouse.yaml", "major", 24.0);
  EXPECT_EQ(st.steps, 12000);
  EXPECT_LT(st.worst_agent_force_N, st.robot_weight_N)
      << st.steps_in_contact << " steps in contact with an agent";
  EXPECT_EQ(st.steps_in_contact, 0);
}

TEST(AgentContactTest, PeopleAskedToPushDoReachTheRobot) {
  // the measurement sees agents' contacts: people that ignore the robot and may push it
  // (npcs.contact: true) walk into the quadruped in the default room
  const testing::TempDir dir;
  const std::string path = (dir.path() / "pushing.yaml").string();
  std::ofstream(path) << "presets:\n  pushing:\n    npcs: {people: 4, speed_m_s: 1.3, "
                         "pause_sec: 0.5, behaviour: ignore, contact: true}\n";
  const ContactStats st = RunUnderPreset("default.yaml", path);
  EXPECT_GT(st.steps_in_contact, 0);
}

}  // namespace
}  // namespace penumbra
