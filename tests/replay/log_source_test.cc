// LogSource: a recorded run walked through the pipeline with no physics gives the snapshots
// live physics gave, bit for bit (poses, sensors, contacts); a replay model with an added agent
// keeps the recorded bodies on the log and moves the new one on its own path.
#include "penumbra/replay/log_source.h"

#include <gtest/gtest.h>

#include <bit>

#include "common/run_loop.h"
#include "common/temp_dir.h"
#include "penumbra/core/error.h"
#include "penumbra/effects/agent_animation.h"
#include "penumbra/effects/agent_path.h"
#include "penumbra/live/run_log_header.h"
#include "penumbra/output/recorder_sink.h"
#include "penumbra/physics/physics_source.h"
#include "penumbra/replay/recorded_world.h"
#include "penumbra/session/session.h"

namespace penumbra {
namespace {

bool SameBits(double a, double b) {
  return std::bit_cast<uint64_t>(a) == std::bit_cast<uint64_t>(b);
}
bool SameBits(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (!SameBits(a[i], b[i])) return false;
  return true;
}
bool SameBits(const Pose& a, const Pose& b) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c)
      if (!SameBits(a.matrix()(r, c), b.matrix()(r, c))) return false;
  return true;
}

// keeps a kFull snapshot every `every` steps and a kPoses one at the others
class Keep final : public Sink {
 public:
  explicit Keep(int every) : every_(every) {}
  SnapshotContent Wants(int64_t step, double) override {
    return step % every_ == 0 ? SnapshotContent::kFull : SnapshotContent::kPoses;
  }
  void OnSnapshot(const std::shared_ptr<const WorldSnapshot>& s) override { kept.push_back(s); }
  std::vector<std::shared_ptr<const WorldSnapshot>> kept;

 private:
  int every_;
};

SessionOptions Replaying() {
  SessionOptions o;
  o.build_renderer = false;
  o.add_controllers = false;
  return o;
}

// the bundled crowd world (a rover with a waypoint controller among six mocap agents), 0.3 s
// recorded with snapshots kept
class LogSourceTest : public ::testing::Test {
 protected:
  void SetUp() override {
    log_ = (tmp_.path() / "crowd.plog").string();
    const WorldConfig world =
        LoadWorldFile(std::string(PENUMBRA_SOURCE_DIR) + "/worlds/effects/crowd.yaml");
    SessionOptions o;
    o.build_renderer = false;
    Session session(world, o);
    PhysicsSource physics(&session.sim());
    RecorderSink recorder(log_, MakeRunLogHeader(session, "test", "penumbra run crowd.yaml"));
    ASSERT_FALSE(testing::RunLoop(&physics, {&live_, &recorder}, 0.3).error);
    ASSERT_EQ(live_.kept.size(), 151u);
  }

  testing::TempDir tmp_;
  std::string log_;
  Keep live_{10};
};

TEST_F(LogSourceTest, ReplayedSnapshotsEqualTheLiveOnesBitForBit) {
  RunLogReader reader = RunLogReader::Open(log_);
  Session session(RecordedWorld(reader.header()), Replaying());
  LogSource source(&reader, &session.sim());
  EXPECT_TRUE(source.state_map().identity());
  Keep replay(10);
  const LoopFinish f = testing::RunLoop(&source, {&replay}, 1e9);
  ASSERT_FALSE(f.error);
  EXPECT_EQ(f.reason, LoopEndReason::kSourceEnded);
  ASSERT_EQ(replay.kept.size(), live_.kept.size());
  size_t contacts = 0;
  for (size_t i = 0; i < replay.kept.size(); ++i) {
    const WorldSnapshot& a = *live_.kept[i];
    const WorldSnapshot& b = *replay.kept[i];
    ASSERT_EQ(a.step, b.step);
    ASSERT_TRUE(SameBits(a.time_sec, b.time_sec));
    ASSERT_TRUE(SameBits(a.qpos, b.qpos)) << "step " << a.step;
    ASSERT_TRUE(SameBits(a.qvel, b.qvel)) << "step " << a.step;
    ASSERT_TRUE(SameBits(a.ctrl, b.ctrl)) << "step " << a.step;
    ASSERT_TRUE(SameBits(a.mocap_pos, b.mocap_pos)) << "step " << a.step;
    EXPECT_EQ(a.controller_next_update, b.controller_next_update);
    ASSERT_EQ(a.X_WB.size(), b.X_WB.size());
    for (size_t k = 0; k < a.X_WB.size(); ++k)
      ASSERT_TRUE(SameBits(a.X_WB[k], b.X_WB[k])) << "step " << a.step << " body " << k;
    ASSERT_TRUE(SameBits(a.sensordata, b.sensordata)) << "step " << a.step;
    ASSERT_EQ(a.contacts.size(), b.contacts.size()) << "step " << a.step;
    for (size_t c = 0; c < a.contacts.size(); ++c) {
      EXPECT_EQ(a.contacts[c].geom1, b.contacts[c].geom1);
      EXPECT_EQ(a.contacts[c].geom2, b.contacts[c].geom2);
      for (int k = 0; k < 3; ++k) {
        ASSERT_TRUE(SameBits(a.contacts[c].force_N[k], b.contacts[c].force_N[k]));
        ASSERT_TRUE(SameBits(a.contacts[c].p_W[k], b.contacts[c].p_W[k]));
      }
    }
    for (size_t k = 0; k < a.V_WB.size(); ++k)
      for (int j = 0; j < 6; ++j) ASSERT_TRUE(SameBits(a.V_WB[k][j], b.V_WB[k][j]));
    contacts += a.contacts.size();
  }
  EXPECT_GT(contacts, 0u);  // the wheels on the floor: the kFull snapshots have contacts
}

TEST_F(LogSourceTest, AnAddedAgentMovesOnItsPathAndTheRecordedBodiesFollowTheLog) {
  RunLogReader reader = RunLogReader::Open(log_);
  WorldConfig world = RecordedWorld(reader.header());
  AgentConfig zed;
  zed.name = "zed";
  zed.waypoints = {{-1.0, -2.0}, {1.0, -2.0}};
  zed.speed_m_s = 2.0;
  world.agents.push_back(zed);
  Session session(world, Replaying());
  LogSource source(&reader, &session.sim());
  EXPECT_FALSE(source.state_map().identity());
  // the added person's root and its limbs (effects/agent_animation.h), root first
  const size_t zed_bodies = 1 + AgentPartNames(AgentKind::kPerson).size();
  ASSERT_EQ(source.state_map().unlogged_mocap().size(), zed_bodies);
  const int zed_mocap = source.state_map().unlogged_mocap()[0];
  Keep replay(10);
  ASSERT_FALSE(testing::RunLoop(&source, {&replay}, 1e9).error);
  ASSERT_EQ(replay.kept.size(), live_.kept.size());
  const AgentPath path(zed);
  for (size_t i = 0; i < replay.kept.size(); ++i) {
    const WorldSnapshot& a = *live_.kept[i];
    const WorldSnapshot& b = *replay.kept[i];
    ASSERT_TRUE(SameBits(a.qpos, b.qpos));
    // every recorded body where it was (the added agent's body comes after them)
    for (size_t k = 0; k < a.X_WB.size(); ++k)
      ASSERT_TRUE(SameBits(a.X_WB[k], b.X_WB[k])) << "step " << a.step << " body " << k;
    ASSERT_EQ(b.X_WB.size(), a.X_WB.size() + zed_bodies);
    // zed where its path says at the step's time (its pelvis bobs with the gait, < 0.1 m)
    const Eigen::Vector3d p = path.X_WA(b.time_sec).translation();
    for (int k = 0; k < 2; ++k) EXPECT_EQ(b.mocap_pos[3 * zed_mocap + k], p[k]);
    EXPECT_NEAR(b.mocap_pos[3 * zed_mocap + 2], p[2], 0.1);
  }
}

TEST_F(LogSourceTest, StartsAtTheFirstLoggedStepAtOrAfterFirstStep) {
  RunLogReader reader = RunLogReader::Open(log_);
  Session session(RecordedWorld(reader.header()), Replaying());
  LogSource source(&reader, &session.sim(), LogSourceOptions{100});
  EXPECT_EQ(source.step(), 100);
  EXPECT_EQ(source.time_sec(), SimTimeOfStep(100, 0.002));
  Keep replay(10);
  ASSERT_FALSE(testing::RunLoop(&source, {&replay}, 1e9).error);
  ASSERT_EQ(replay.kept.size(), 51u);
  EXPECT_TRUE(SameBits(replay.kept.front()->qpos, live_.kept[100]->qpos));

  RunLogReader again = RunLogReader::Open(log_);
  EXPECT_THROW(LogSource(&again, &session.sim(), LogSourceOptions{151}), RunLogError);
}

TEST_F(LogSourceTest, AnotherTimestepOrAMissingJointIsRefused) {
  RunLogReader reader = RunLogReader::Open(log_);
  WorldConfig world = RecordedWorld(reader.header());
  world.timestep_sec = 0.001;
  Session faster(world, Replaying());
  try {
    LogSource source(&reader, &faster.sim());
    ADD_FAILURE();
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.file(), log_);
    EXPECT_NE(std::string(e.what()).find("timestep is 0.001"), std::string::npos) << e.what();
  }
  // the rover left out: its joints are missing
  world = RecordedWorld(reader.header());
  world.models.erase(world.models.begin());
  world.cameras.erase(world.cameras.begin());  // `front` rides on the rover
  Session no_rover(world, Replaying());
  try {
    LogSource source(&reader, &no_rover.sim());
    ADD_FAILURE();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("the replay model has no joint 'rover/"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace penumbra
