// a run with a crowd recorded and replayed: the run log holds every agent's pose and
// the crowd's decisions ("npc" events), and a kinematic replay (replay/log_source.h) poses the
// agents exactly where the run had them.

#include <gtest/gtest.h>

#include <bit>
#include <filesystem>
#include <fstream>

#include "common/run_loop.h"
#include "common/temp_dir.h"
#include "penumbra/compose/agent_bodies.h"
#include "penumbra/live/run_log_header.h"
#include "penumbra/output/recorder_sink.h"
#include "penumbra/physics/physics_source.h"
#include "penumbra/replay/log_source.h"
#include "penumbra/replay/recorded_world.h"
#include "penumbra/runlog/run_log_reader.h"
#include "penumbra/session/session.h"

namespace penumbra {
namespace {

TEST(CrowdReplayTest, ReplayPosesTheCrowdAsTheRunDid) {
  const testing::TempDir dir;
  const std::string preset = (dir.path() / "crowd_preset.yaml").string();
  std::ofstream(preset) << "presets:\n  crowd:\n    npcs: {people: 4}\n";
  const std::string path = (dir.path() / "crowd.plog").string();
  const WorldConfig world = LoadWorldFile(std::string(PENUMBRA_SOURCE_DIR) + "/worlds/house.yaml");
  SessionOptions o;
  o.build_renderer = false;
  o.adversity = preset;
  std::vector<std::string> names;
  {
    Session session(world, o);
    for (const AgentConfig& a : session.effects().agents()) names.push_back(a.name);
    PhysicsSource physics(&session.sim());
    RunLogWriterOptions wo;
    wo.chunk_steps = 64;
    RecorderSink recorder(path, MakeRunLogHeader(session, "test", "run crowd"), wo);
    session.effects().set_crowd_decision_sink([&](double t, const std::string& json) {
      recorder.writer().RecordEvent(std::llround(t / 0.002), t, "npc", json);
    });
    const LoopFinish f = testing::RunLoop(&physics, {&recorder}, 1.5);
    ASSERT_FALSE(f.error);
  }
  ASSERT_EQ(names.size(), 4u);

  RunLogReader log = RunLogReader::Open(path);
  int npc_events = 0;
  RunLogRecord record;
  while (log.NextRecord(&record))
    if (const auto* e = std::get_if<EventRecord>(&record))
      if (e->kind == "npc") {
        ++npc_events;
        EXPECT_NE(e->payload.find("\"agent\""), std::string::npos);
      }
  EXPECT_GE(npc_events, 4);  // every person's first goal

  // the replay model (no controllers) posed from the log
  SessionOptions ro = o;
  ro.add_controllers = false;
  Session replay(world, ro);
  std::vector<int> bodies;
  for (const std::string& n : names) bodies.push_back(replay.scene().FindBody(AgentBodyName(n)));
  LogSource source(&log, &replay.sim());
  StepRecord logged;
  RunLogReader steps = RunLogReader::Open(path);
  int compared = 0;
  double moved = 0;
  Eigen::Vector3d first = Eigen::Vector3d::Zero();
  do {
    ASSERT_TRUE(steps.NextStep(&logged));
    ASSERT_EQ(logged.step, source.step());
    const std::shared_ptr<const WorldSnapshot> snap = source.Snapshot(SnapshotContent::kPoses);
    for (size_t i = 0; i < bodies.size(); ++i) {
      ASSERT_GE(bodies[i], 0);
      const Eigen::Vector3d p = snap->X_WB[bodies[i]].translation();
      // the log's mocap_pos of that agent (mocap bodies in the log's order)
      const auto& mnames = log.header().layout.mocap_body_names;
      const auto it = std::find(mnames.begin(), mnames.end(), AgentBodyName(names[i]));
      ASSERT_NE(it, mnames.end());
      const size_t m = it - mnames.begin();
      for (int k = 0; k < 3; ++k)
        EXPECT_EQ(std::bit_cast<uint64_t>(p[k]),
                  std::bit_cast<uint64_t>(logged.mocap_pos[3 * m + k]));
      if (i == 0 && compared == 0) first = p;
      if (i == 0) moved = std::max(moved, (p - first).norm());
    }
    ++compared;
  } while (source.Advance());
  EXPECT_EQ(compared, 751);  // steps 0..750 at 2 ms
  EXPECT_GT(moved, 0.5);     // the first person walked during the 1.5 s
}

TEST(CrowdReplayTest, ARecordedCommandLinesBlockGoalPresetPlacesTheSameCrowd) {
  // what penumbra benchmark runs (campaign/nav_job.h): --adversity FILE#NAME of a block preset
  // with the episode's goal; a replay reads the spec back from the recorded command line and
  // plans the same people, which the goal moved (here to the rover's route behind its start)
  const testing::TempDir dir;
  const std::string file = (dir.path() / "adversity.yaml").string();
  std::ofstream(file) << "presets:\n  major:\n    npcs: {people: 4, speed_m_s: 0.8, behaviour: "
                         "block, block_goal: [-2.5, 0.1]}\n  ahead:\n    npcs: {people: 4, "
                         "speed_m_s: 0.8, behaviour: block}\n";
  const std::string spec = file + "#major";
  const RecordedRunFlags flags = ParseRecordedRunFlags(
      "penumbra run worlds/rover.yaml --out run --lockstep --adversity " + spec + " --seed 2");
  EXPECT_EQ(flags.adversity, spec);
  WorldConfig world = LoadWorldFile(std::string(PENUMBRA_SOURCE_DIR) + "/worlds/rover.yaml");
  world.seed = 2;
  const auto starts = [&](const std::string& adversity) {
    SessionOptions o;
    o.build_renderer = false;
    o.adversity = adversity;
    const Session session(world, o);
    std::vector<double> out;
    for (const AgentConfig& a : session.effects().agents())
      out.insert(out.end(), {a.waypoints[0].x(), a.waypoints[0].y()});
    return out;
  };
  const std::vector<double> run = starts(spec), replay = starts(flags.adversity);
  ASSERT_EQ(run.size(), 8u);
  EXPECT_EQ(run, replay);                   // bit for bit
  EXPECT_NE(run, starts(file + "#ahead"));  // the goal changed where they start
}

}  // namespace
}  // namespace penumbra
