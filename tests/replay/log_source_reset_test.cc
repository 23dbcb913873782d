// LogSource replays the log's `reset` commands as episode starts: the replay model's
// controller episode start (what the sensor and camera sinks restart their schedules and noise
// streams on) moves at the steps it moved in the run; the world's agents restart with each
// episode in the run and the replay shows them where the run had them.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "common/run_loop.h"
#include "common/temp_dir.h"
#include "penumbra/live/run_log_header.h"
#include "penumbra/output/recorder_sink.h"
#include "penumbra/physics/physics_source.h"
#include "penumbra/replay/log_source.h"
#include "penumbra/replay/recorded_world.h"
#include "penumbra/runlog/run_log_reader.h"
#include "penumbra/session/session.h"

namespace penumbra {
namespace {

// (step, the simulation's controller episode start) at every step, as a sink reads it in Wants,
// and the poses (X_WB) of the agents' bodies in every snapshot
class EpisodeProbe final : public Sink {
 public:
  explicit EpisodeProbe(const Simulation* sim) : sim_(sim) {
    const auto& bodies = sim->scene().bodies;
    for (size_t b = 0; b < bodies.size(); ++b)
      if (bodies[b].name.rfind("agents/", 0) == 0) agent_bodies_.push_back(b);
  }
  SnapshotContent Wants(int64_t step, double) override {
    seen.emplace_back(step, sim_->controller_episode_start());
    return SnapshotContent::kPoses;
  }
  void OnSnapshot(const std::shared_ptr<const WorldSnapshot>& snapshot) override {
    std::vector<double> m;
    for (const size_t b : agent_bodies_) {
      const Eigen::Matrix<double, 3, 4> X = snapshot->X_WB.at(b).matrix().topRows<3>();
      m.insert(m.end(), X.data(), X.data() + 12);
    }
    agents.push_back(std::move(m));
  }
  std::vector<std::pair<int64_t, int64_t>> seen;
  std::vector<std::vector<double>> agents;

 private:
  const Simulation* sim_;
  std::vector<size_t> agent_bodies_;
};

TEST(LogSourceResetTest, TheLogsResetsStartEpisodesAtTheirSteps) {
  testing::TempDir tmp;
  const std::string log = (tmp.path() / "resets.plog").string();
  const WorldConfig world =
      LoadWorldFile(std::string(PENUMBRA_SOURCE_DIR) + "/worlds/effects/crowd.yaml");
  std::vector<std::pair<int64_t, int64_t>> live_seen;
  std::vector<std::vector<double>> live_agents;
  {
    SessionOptions o;
    o.build_renderer = false;
    Session session(world, o);
    Simulation& sim = session.sim();
    const SimState initial = sim.GetState();
    RecorderSink recorder(log, MakeRunLogHeader(session, "test", "penumbra run crowd.yaml"));
    // what the `reset` command does at a step boundary (command/command_dispatcher.cc), and
    // the command events a live run logs (a twist is no reset)
    PhysicsSourceOptions po;
    po.before_step = [&](Simulation& s) {
      const int64_t step = s.step_count();
      if (step == 20)
        recorder.writer().RecordEvent(step, s.time(), "command", R"({"cmd":"twist","vx":0.1})");
      if (step == 40 || step == 97) {
        const SimState now = s.GetState();
        SimState r = initial;
        r.step = now.step;
        r.time_sec = now.time_sec;
        r.controller_next_update = now.controller_next_update;
        s.SetState(r);
        s.ResetControllers();
        recorder.writer().RecordEvent(step, s.time(), "command", R"({"cmd":"reset"})");
      }
      return true;
    };
    PhysicsSource physics(&sim, po);
    EpisodeProbe probe(&sim);
    ASSERT_FALSE(testing::RunLoop(&physics, {&probe, &recorder}, 0.3).error);
    live_seen = probe.seen;
    live_agents = probe.agents;
  }
  ASSERT_EQ(live_seen.size(), 151u);
  EXPECT_EQ(live_seen[40].second, 0);
  EXPECT_EQ(live_seen[41].second, 40);
  EXPECT_EQ(live_seen[98].second, 97);
  // the walkers restart with each episode (episodes: steps 0-40, 40-97, 97-150): an episode's
  // step k poses them as every other episode's step k
  ASSERT_EQ(live_agents.size(), 151u);
  ASSERT_GE(live_agents[1].size(), 6u * 12u);  // crowd.yaml: 6 agents, their parts
  EXPECT_NE(live_agents[40], live_agents[1]);
  for (int k = 1; k <= 53; ++k) {
    if (k <= 40) EXPECT_EQ(live_agents[40 + k], live_agents[k]) << "episode step " << k;
    EXPECT_EQ(live_agents[97 + k], live_agents[40 + k]) << "episode step " << k;
  }

  RunLogReader reader = RunLogReader::Open(log);
  SessionOptions replaying;
  replaying.build_renderer = false;
  replaying.add_controllers = false;
  Session session(RecordedWorld(reader.header()), replaying);
  LogSource source(&reader, &session.sim());
  EpisodeProbe probe(&session.sim());
  ASSERT_FALSE(testing::RunLoop(&source, {&probe}, 1e9).error);
  EXPECT_EQ(probe.seen, live_seen);
  // the replay's agents are where the run had them (the log's mocap poses) at every step
  EXPECT_EQ(probe.agents, live_agents);
}

}  // namespace
}  // namespace penumbra
