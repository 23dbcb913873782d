// LogSource replays the log's `reset` commands as episode starts: the replay model's
// controller episode start (what the sensor and camera sinks restart their schedules and noise
// streams on) moves at the steps it moved in the run.
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

// (step, the simulation's controller episode start) at every step, as a sink reads it in Wants
class EpisodeProbe final : public Sink {
 public:
  explicit EpisodeProbe(const Simulation* sim) : sim_(sim) {}
  SnapshotContent Wants(int64_t step, double) override {
    seen.emplace_back(step, sim_->controller_episode_start());
    return SnapshotContent::kNone;
  }
  void OnSnapshot(const std::shared_ptr<const WorldSnapshot>&) override {}
  std::vector<std::pair<int64_t, int64_t>> seen;

 private:
  const Simulation* sim_;
};

TEST(LogSourceResetTest, TheLogsResetsStartEpisodesAtTheirSteps) {
  testing::TempDir tmp;
  const std::string log = (tmp.path() / "resets.plog").string();
  const WorldConfig world =
      LoadWorldFile(std::string(PENUMBRA_SOURCE_DIR) + "/worlds/effects/crowd.yaml");
  std::vector<std::pair<int64_t, int64_t>> live_seen;
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
  }
  ASSERT_EQ(live_seen.size(), 151u);
  EXPECT_EQ(live_seen[40].second, 0);
  EXPECT_EQ(live_seen[41].second, 40);
  EXPECT_EQ(live_seen[98].second, 97);

  RunLogReader reader = RunLogReader::Open(log);
  SessionOptions replaying;
  replaying.build_renderer = false;
  replaying.add_controllers = false;
  Session session(RecordedWorld(reader.header()), replaying);
  LogSource source(&reader, &session.sim());
  EpisodeProbe probe(&session.sim());
  ASSERT_FALSE(testing::RunLoop(&source, {&probe}, 1e9).error);
  EXPECT_EQ(probe.seen, live_seen);
}

}  // namespace
}  // namespace penumbra
