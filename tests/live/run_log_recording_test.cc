// recording a run through the pipeline (output/recorder_sink.h, live/run_log_header.h): the
// log's step records are the simulation's own state (Simulation::GetState) at every step,
// bit for bit, from step 0; the header maps that state by name and hashes the files read.

#include <gtest/gtest.h>

#include <bit>
#include <filesystem>

#include "common/run_loop.h"
#include "common/temp_dir.h"
#include "penumbra/core/error.h"
#include "penumbra/live/live_recorder.h"
#include "penumbra/live/run_log_header.h"
#include "penumbra/output/recorder_sink.h"
#include "penumbra/physics/physics_source.h"
#include "penumbra/runlog/run_log_reader.h"
#include "penumbra/session/session.h"

namespace penumbra {
namespace {

template <typename T>
bool SameBits(const std::vector<T>& a, const std::vector<T>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (std::bit_cast<uint64_t>(a[i]) != std::bit_cast<uint64_t>(b[i])) return false;
  return true;
}

// the bundled crowd world: a rover with a waypoint controller among six mocap agents (every
// part of the state is in use: qpos/qvel, ctrl, controllers' schedule, mocap poses)
WorldConfig CrowdWorld() {
  return LoadWorldFile(std::string(PENUMBRA_SOURCE_DIR) + "/worlds/effects/crowd.yaml");
}

SessionOptions PhysicsOnly() {
  SessionOptions o;
  o.build_renderer = false;
  return o;
}

TEST(RunLogRecordingTest, RecordedStatesEqualAFreshSimulationsStateAtEveryStep) {
  testing::TempDir tmp;
  const std::string path = (tmp.path() / "crowd.plog").string();
  const WorldConfig world = CrowdWorld();
  {
    Session session(world, PhysicsOnly());
    PhysicsSource physics(&session.sim());
    RunLogWriterOptions o;
    o.chunk_steps = 32;
    RecorderSink recorder(path, MakeRunLogHeader(session, "test", "run crowd"), o);
    const LoopFinish f = testing::RunLoop(&physics, {&recorder}, 0.3);
    ASSERT_FALSE(f.error);
    EXPECT_EQ(recorder.stats().steps, 151);  // steps 0..150 at 2 ms
  }

  RunLogReader log = RunLogReader::Open(path);
  EXPECT_TRUE(log.complete());
  EXPECT_EQ(log.first_step(), 0);
  EXPECT_EQ(log.last_step(), 150);
  Session fresh(world, PhysicsOnly());
  Simulation& sim = fresh.sim();
  StepRecord r;
  int64_t n = 0;
  while (log.NextStep(&r)) {
    // as the run's PhysicsSource did before its first snapshot (Simulation::RunDueControllers)
    if (r.step == 0) sim.RunDueControllers();
    const SimState s = sim.GetState();
    ASSERT_EQ(r.step, s.step);
    EXPECT_EQ(std::bit_cast<uint64_t>(r.time_sec), std::bit_cast<uint64_t>(s.time_sec));
    EXPECT_TRUE(SameBits(r.qpos, s.qpos)) << r.step;
    EXPECT_TRUE(SameBits(r.qvel, s.qvel)) << r.step;
    EXPECT_TRUE(SameBits(r.act, s.act)) << r.step;
    EXPECT_TRUE(SameBits(r.ctrl, s.ctrl)) << r.step;
    EXPECT_TRUE(SameBits(r.qacc_warmstart, s.qacc_warmstart)) << r.step;
    EXPECT_TRUE(SameBits(r.qfrc_applied, s.qfrc_applied)) << r.step;
    EXPECT_TRUE(SameBits(r.xfrc_applied, s.xfrc_applied)) << r.step;
    EXPECT_TRUE(SameBits(r.mocap_pos, s.mocap_pos)) << r.step;
    EXPECT_TRUE(SameBits(r.mocap_quat, s.mocap_quat)) << r.step;
    EXPECT_TRUE(SameBits(r.userdata, s.userdata)) << r.step;
    EXPECT_EQ(r.controller_next_update, s.controller_next_update) << r.step;
    sim.Step();
    ++n;
  }
  EXPECT_EQ(n, 151);
}

TEST(RunLogRecordingTest, TheHeaderMapsTheStateByNameAndHashesTheFilesRead) {
  testing::TempDir tmp;
  const WorldConfig world = CrowdWorld();
  Session session(world, PhysicsOnly());
  const RunLogHeader h = MakeRunLogHeader(session, "1.2.3", "penumbra run crowd.yaml");
  EXPECT_EQ(h.penumbra_version, "1.2.3");
  EXPECT_EQ(h.mujoco_version, "4.0.0");  // the pinned wheel (scripts/requirements.txt)
  EXPECT_EQ(h.world_file, std::filesystem::path(world.file).lexically_normal().string());
  EXPECT_NE(h.world_text.find("name: rover"), std::string::npos);
  EXPECT_EQ(h.composed_mjcf, session.composed_xml());
  EXPECT_EQ(h.seed, 7u);
  EXPECT_EQ(h.timestep_sec, 0.002);
  const SimState s = session.sim().GetState();
  const RunLogLayout& l = h.layout;
  EXPECT_EQ(l.nq, static_cast<int>(s.qpos.size()));
  EXPECT_EQ(l.nv, static_cast<int>(s.qvel.size()));
  EXPECT_EQ(l.nu, static_cast<int>(s.ctrl.size()));
  // six agents: five people (root + 8 limbs) and a forklift (root + 4 wheels)
  EXPECT_EQ(l.nmocap, 5 * 9 + 5);
  EXPECT_EQ(l.num_controllers, 1);
  EXPECT_EQ(l.controller_names, std::vector<std::string>{"waypoint_follower"});
  EXPECT_EQ(static_cast<int>(l.body_names.size()), l.nbody);
  EXPECT_EQ(static_cast<int>(l.mocap_body_names.size()), 5 * 9 + 5);
  // the rover's free joint: 7 qpos entries at its address, 6 qvel
  bool found_free = false;
  for (const RunLogJoint& j : l.joints)
    if (j.type == "free" && j.name.rfind("rover/", 0) == 0) {
      found_free = true;
      EXPECT_EQ(j.qpos_width, 7);
      EXPECT_EQ(j.qvel_width, 6);
    }
  EXPECT_TRUE(found_free);
  EXPECT_NE(std::find(l.actuator_names.begin(), l.actuator_names.end(), "rover/left_wheel"),
            l.actuator_names.end());
  // the world, both models, and the room's meshes or textures, each with its SHA-256
  int worlds = 0, models = 0;
  for (const RunLogAsset& a : h.assets) {
    worlds += a.role == "world";
    models += a.role == "model";
    EXPECT_EQ(a.sha256.size(), 64u) << a.path;
    EXPECT_EQ(a.sha256, Sha256OfFile(a.path)) << a.path;
  }
  EXPECT_EQ(worlds, 1);
  EXPECT_EQ(models, 2);
}

// a live recording started as the run stops gets no step; it is removed, not left as
// an empty log, and once the loop has finished no recording can start
TEST(RunLogRecordingTest, ALiveRecordingThatGotNoStepIsRemovedAndNoneStartsAfterTheEnd) {
  testing::TempDir tmp;
  Session session(CrowdWorld(), PhysicsOnly());
  LiveRecorder recorder(session, "penumbra run crowd.yaml", tmp.path());
  const std::filesystem::path late = tmp.path() / "late.plog";
  recorder.StartRecording("late.plog", false);
  ASSERT_TRUE(std::filesystem::exists(late));  // the header is written at once
  EXPECT_FALSE(recorder.finished());
  recorder.OnFinish(LoopFinish{});
  EXPECT_TRUE(recorder.finished());
  EXPECT_FALSE(recorder.recording());
  EXPECT_FALSE(std::filesystem::exists(late));
  EXPECT_EQ(recorder.closed_at_finish().path, "");
  const std::filesystem::path after = tmp.path() / "after.plog";
  try {
    recorder.StartRecording("after.plog", false);
    ADD_FAILURE() << "a recording started after the loop finished";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "recording");
    EXPECT_NE(std::string(e.what()).find("the run has ended"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(after));
}

}  // namespace
}  // namespace penumbra
