// agents a kinematic replay adds (an --adversity preset's NPCs, an override's `agents:`) move on
// their own while the robot moves as logged: crowd agents keep clear of the logged robot, as
// they would have in a run, and agents that may touch it (npcs.contact, behaviour block,
// scripted paths) are refused with the reason instead of passing through it. (a replay of a
// run under `major` once drove its forklift through the robot.)

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "common/run_loop.h"
#include "common/temp_dir.h"
#include "penumbra/compose/agent_bodies.h"
#include "penumbra/core/error.h"
#include "penumbra/live/run_log_header.h"
#include "penumbra/output/recorder_sink.h"
#include "penumbra/physics/physics_source.h"
#include "penumbra/replay/kinematic/replay_runner.h"
#include "penumbra/replay/log_source.h"
#include "penumbra/runlog/run_log_reader.h"
#include "penumbra/session/crowd_runner.h"
#include "penumbra/session/session.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

// the rover trotting its lap of the default room, recorded without adversity for `seconds`
class AgentReplayTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new testing::TempDir();
    log_ = (dir_->path() / "rover.plog").string();
    world_ = LoadWorldFile(std::string(PENUMBRA_SOURCE_DIR) + "/worlds/rover.yaml");
    SessionOptions o;
    o.build_renderer = false;
    Session session(world_, o);
    PhysicsSource physics(&session.sim());
    RecorderSink recorder(log_, MakeRunLogHeader(session, "test", "penumbra run rover.yaml"),
                          RunLogWriterOptions{});
    ASSERT_FALSE(testing::RunLoop(&physics, {&recorder}, kSeconds).error);
  }
  static void TearDownTestSuite() { delete dir_; }

  // a one-preset file `name` with `npcs`
  static std::string Preset(const std::string& name, const std::string& npcs) {
    const std::string path = (dir_->path() / (name + ".yaml")).string();
    std::ofstream(path) << "presets:\n  " << name << ":\n    npcs: " << npcs << "\n";
    return path;
  }

  // the ConfigError of a kinematic replay of the log with these changes ("" = none)
  static std::string ReplayError(const std::string& adversity, const std::string& override_yaml) {
    ReplayOptions o;
    o.log_path = log_;
    o.out_dir = (dir_->path() / "replay").string();
    o.force = true;
    o.progress = false;
    o.adversity = adversity;
    if (!override_yaml.empty()) {
      o.world_override = (dir_->path() / "override.yaml").string();
      std::ofstream(o.world_override) << override_yaml;
    }
    try {
      ReplayLog(o);
    } catch (const ConfigError& e) {
      return e.what();
    }
    return "";
  }

  static constexpr double kSeconds = 8.0;
  static testing::TempDir* dir_;
  static std::string log_;
  static WorldConfig world_;
};

testing::TempDir* AgentReplayTest::dir_ = nullptr;
std::string AgentReplayTest::log_;
WorldConfig AgentReplayTest::world_;

TEST_F(AgentReplayTest, AddedAgentsThatMayTouchTheRobotAreRefusedWithTheReason) {
  std::string e = ReplayError(Preset("pushing", "{people: 2, contact: true}"), "");
  EXPECT_NE(e.find("--adversity: agent 'adversity_person0' is not in the log and may touch the "
                   "robot (the preset's npcs.contact: true); a replay moves the robot as logged"),
            std::string::npos)
      << e;
  e = ReplayError(Preset("blocking", "{people: 2, behaviour: block}"), "");
  EXPECT_NE(e.find("may touch the robot (behaviour: block stands in the robot's way)"),
            std::string::npos)
      << e;
  e = ReplayError("", "agents:\n  - {name: zed, waypoints: [[-2, -1.5], [2, -1.5]]}\n");
  EXPECT_NE(e.find("agents: agent 'zed' is not in the log and may touch the robot (motion: "
                   "scripted follows its path whatever it touches)"),
            std::string::npos)
      << e;
  EXPECT_FALSE(fs::exists(dir_->path() / "replay" / "run.json"));
}

// the nearest approach (plan, m) of the people of preset `npcs` to the rover during a kinematic
// replay of the log that adds them, the rover's crowd disc radius, and how far it drove
struct Approach {
  double nearest_m = 1e9, disc_m = 0, rover_moved_m = 0;
  int steps = 0;
};

Approach ReplayWithPeople(const WorldConfig& world, const std::string& log,
                          const std::string& preset) {
  SessionOptions o;
  o.build_renderer = false;
  o.add_controllers = false;
  o.adversity = preset;
  Session replay(world, o);
  RunLogReader reader = RunLogReader::Open(log);
  LogSource source(&reader, &replay.sim());
  const std::vector<CrowdRobotSource> robots = CrowdRobotsOf(world.models, replay.sim());
  Approach out;
  if (robots.size() != 1) return out;
  out.disc_m = robots[0].radius_m;
  const int rover = replay.scene().FindBody("rover/chassis");
  std::vector<int> people;
  for (const AgentConfig& a : replay.effects().agents())
    people.push_back(replay.scene().FindBody(AgentBodyName(a.name)));
  Eigen::Vector2d rover_start(0, 0);
  do {
    const std::shared_ptr<const WorldSnapshot> s = source.Snapshot(SnapshotContent::kPoses);
    const Eigen::Vector2d r = s->X_WB[rover].translation().head<2>();
    if (out.steps == 0) rover_start = r;
    out.rover_moved_m = std::max(out.rover_moved_m, (r - rover_start).norm());
    for (const int p : people)
      out.nearest_m = std::min(out.nearest_m, (s->X_WB[p].translation().head<2>() - r).norm());
    ++out.steps;
  } while (source.Advance());
  return out;
}

TEST_F(AgentReplayTest, AddedCrowdAgentsKeepClearOfTheLoggedRobot) {
  // six people who ignore robots (no planning or steering round them) but may not push: in the
  // replay they see the rover where the log has it and never come into its contact disc
  const Approach a =
      ReplayWithPeople(world_, log_, Preset("walkers", "{people: 6, behaviour: ignore}"));
  EXPECT_EQ(a.steps, static_cast<int>(kSeconds / 0.002) + 1);
  EXPECT_GT(a.rover_moved_m, 1.0);  // the logged rover drove
  std::printf("nearest person to the logged rover: %.3f m (its disc %.3f m)\n", a.nearest_m,
              a.disc_m);
  // the contact disc: the rover's disc + a person's reach (0.3 m) + 0.02 m, less what the
  // rover moves in one crowd step (0.05 s at 0.5 m/s)
  EXPECT_GE(a.nearest_m, a.disc_m + 0.3 + 0.02 - 0.025);
  EXPECT_LT(a.nearest_m, a.disc_m + 1.0);  // they did come near it
  // the same people allowed to push (which a replay refuses) walk into the rover's disc
  const Approach pushing = ReplayWithPeople(
      world_, log_, Preset("pushers", "{people: 6, behaviour: ignore, contact: true}"));
  std::printf("with contact: true: %.3f m\n", pushing.nearest_m);
  EXPECT_LT(pushing.nearest_m, pushing.disc_m);
}

}  // namespace
}  // namespace penumbra
