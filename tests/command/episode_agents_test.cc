// `reset` restarts a world's agents and effects with the episode: scripted paths and the crowd
// (ORCA, A*, its random goals) from their start, light events and rain at the episode's time. so
// the same actions after a reset give the first episode's physics state, agent poses and
// effects frames bit for bit, in a room with a walking person, a crowd person, a flickering lamp
// and rain.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "command/live_loop.h"
#include "common/temp_dir.h"
#include "penumbra/command/command_dispatcher.h"
#include "penumbra/compose/agent_bodies.h"
#include "penumbra/pipeline/sink.h"
#include "penumbra/session/session.h"

namespace penumbra {
namespace episode_agents_test {
namespace {

using json = nlohmann::json;
using penumbra::testing::LiveLoop;

// the room of worlds/effects/crowd.yaml with its rover, one scripted walker, one crowd person
// with random goals, a flickering lamp and rain
std::string World() {
  const std::string models = std::string(PENUMBRA_SOURCE_DIR) + "/worlds/models/";
  return R"(seed: 7
physics: {timestep_sec: 0.002}
render: {tier: realtime}
robots:
  - name: rover
    file: )" +
         models +
         R"(rover.xml
    pose: {xyz: [-0.2, -1.45, 0], rpy_deg: [0, 0, 17]}
    controller:
      type: waypoint_follower
      base_body: chassis
      left_actuator: left_wheel
      right_actuator: right_wheel
      wheel_radius_m: 0.05
      track_width_m: 0.3
      speed_m_s: 0.5
      waypoints: [[1.3, -1.0], [1.9, 0.0], [1.4, 1.0]]
      tolerance_m: 0.15
models:
  - {name: room, file: )" +
         models + R"(room.xml}
lights:
  - {name: lamp1, type: point, position: [-2.5, 0.0, 2.58], intensity_cd: 400}
  - {name: lamp2, type: point, position: [0.0, 0.0, 2.58], intensity_cd: 400}
agents:
  - {name: alice, waypoints: [[-2.0, 1.5], [1.8, 1.5], [1.8, -1.0]], speed_m_s: 1.2}
  - {name: guide, motion: crowd, goals: random, speed_m_s: 1.4, waypoints: [[-2, 1.0], [1.8, 0.5], [1.8, -1]]}
effects:
  - {name: flick, type: light_event, light: lamp2, mode: flicker, frequency_hz: 20, depth: 0.8}
  - {name: storm, type: rain, rate_mm_h: 20, wind_m_s: [2, 0, 0]}
)";
}

// what one step shows: every body's pose (robot and agents) and the effects a fixed viewer sees
struct Seen {
  int64_t step = 0;
  std::vector<double> poses;   // X_WB of every body, 12 doubles each
  std::vector<float> effects;  // light scales, then every particle's position and velocity
  std::vector<double> agents;  // the agents' root positions (x, y)
};

class Recorder : public Sink {
 public:
  Recorder(EffectsStage* effects, std::vector<int> agent_bodies)
      : effects_(effects), agent_bodies_(std::move(agent_bodies)) {}
  SnapshotContent Wants(int64_t, double) override { return SnapshotContent::kPoses; }
  void OnSnapshot(const std::shared_ptr<const WorldSnapshot>& snapshot) override {
    Seen s;
    s.step = snapshot->step;
    for (const Pose& X : snapshot->X_WB) {
      const Eigen::Matrix<double, 3, 4> m = X.matrix().topRows<3>();
      s.poses.insert(s.poses.end(), m.data(), m.data() + 12);
    }
    for (const int b : agent_bodies_)
      s.agents.insert(s.agents.end(),
                      {snapshot->X_WB[b].translation().x(), snapshot->X_WB[b].translation().y()});
    // the effects every 20th step of the episode (the rain's drops are many)
    const std::shared_ptr<const EffectsFrame> fx =
        (snapshot->step - snapshot->episode_start_step) % 20 == 0
            ? effects_->Evaluate(*snapshot, Eigen::Vector3d(0, -1, 1.2))
            : nullptr;
    if (fx) {
      s.effects = fx->light_intensity_scale;
      for (const ParticleSet& p : fx->particles)
        for (size_t i = 0; i < p.position_W.size(); ++i)
          s.effects.insert(s.effects.end(),
                           {p.position_W[i].x(), p.position_W[i].y(), p.position_W[i].z(),
                            p.velocity_W[i].x(), p.velocity_W[i].y(), p.velocity_W[i].z()});
    }
    std::lock_guard<std::mutex> lock(mu_);
    seen_.push_back(std::move(s));
  }
  std::vector<Seen> seen() {
    std::lock_guard<std::mutex> lock(mu_);
    return seen_;
  }

 private:
  EffectsStage* effects_;
  std::vector<int> agent_bodies_;
  std::mutex mu_;
  std::vector<Seen> seen_;
};

// the steps in (start, start + steps] (from step 0 for the first episode) by step in the episode
std::map<int64_t, const Seen*> EpisodeOf(const std::vector<Seen>& all, int64_t start, int steps) {
  std::map<int64_t, const Seen*> out;
  for (const Seen& s : all)
    if (s.step >= start && (start == 0 || s.step > start) && s.step <= start + steps)
      out[s.step - start] = &s;
  return out;
}

bool SameBits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}
bool SameBits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

TEST(EpisodeAgentsTest, SameActionsAfterResetGiveTheFirstEpisodesAgentsAndEffectsBitForBit) {
  penumbra::testing::TempDir dir;
  const std::string world = dir.Write("world.yaml", World());
  std::unique_ptr<Recorder> recorder;
  const int steps = 400;  // 0.8 s: the crowd steps, plans and the walkers move
  std::vector<int64_t> starts = {0};
  {
    LiveLoop live(world, 1000.0, [&](Session& session, SimLoop& loop) {
      std::vector<int> agents;
      const SceneDescription& scene = session.sim().scene();
      for (const std::string name : {"alice", "guide"})
        for (size_t b = 0; b < scene.bodies.size(); ++b)
          if (scene.bodies[b].name == AgentBodyName(name)) agents.push_back(static_cast<int>(b));
      ASSERT_EQ(agents.size(), 2u);
      ASSERT_NE(session.effects().crowd(), nullptr);
      recorder = std::make_unique<Recorder>(&session.effects(), agents);
      loop.AddSink(recorder.get());
    });
    live.CallOk({{"cmd", "step"}, {"n", steps}});
    // episodes of other lengths before each reset: an odd step, one off every grid
    for (int before : {37, 161}) {
      live.CallOk({{"cmd", "step"}, {"n", before}});
      const json r = live.CallOk({{"cmd", "reset"}});
      starts.push_back(r.at("step").get<int64_t>());
      live.CallOk({{"cmd", "step"}, {"n", steps}});
    }
    live.Stop();
  }
  const std::vector<Seen> seen = recorder->seen();
  const std::map<int64_t, const Seen*> first = EpisodeOf(seen, 0, steps);
  ASSERT_EQ(first.size(), static_cast<size_t>(steps + 1));
  // the agents walk, the lamp flickers, the rain falls: nothing compared below stands still
  const Seen& a = *first.at(1);
  const Seen& b = *first.at(steps);
  ASSERT_EQ(a.agents.size(), 4u);
  EXPECT_GT(std::hypot(b.agents[0] - a.agents[0], b.agents[1] - a.agents[1]), 0.3) << "alice";
  EXPECT_GT(std::hypot(b.agents[2] - a.agents[2], b.agents[3] - a.agents[3]), 0.3) << "guide";
  ASSERT_FALSE(first.at(20)->effects.empty());
  EXPECT_NE(first.at(20)->effects, b.effects);
  for (size_t e = 1; e < starts.size(); ++e) {
    const std::map<int64_t, const Seen*> again = EpisodeOf(seen, starts[e], steps);
    // the reset step shows the episode before it; the new one from its step 1 on
    ASSERT_EQ(again.size(), static_cast<size_t>(steps));
    for (const auto& [j, s] : again) {
      const Seen& f = *first.at(j);
      ASSERT_TRUE(SameBits(s->poses, f.poses))
          << "episode " << e << " (reset at step " << starts[e]
          << "): body poses differ from the first episode's at its step " << j << " (agents "
          << s->agents[0] << " " << s->agents[1] << ", " << s->agents[2] << " " << s->agents[3]
          << " vs " << f.agents[0] << " " << f.agents[1] << ", " << f.agents[2] << " "
          << f.agents[3] << ")";
      ASSERT_TRUE(SameBits(s->effects, f.effects))
          << "episode " << e << ": effects differ from the first episode's at its step " << j;
    }
  }
}

}  // namespace
}  // namespace episode_agents_test
}  // namespace penumbra
