// `reset` starts an episode: the physics state of step 0 and every controller back to its
// just-initialized state on a clock that restarts at 0. so the same actions after a reset give
// the qpos and qvel of the run's first episode bit for bit, whatever ran before the reset and at
// whichever step it comes, for every controller type (bundled worlds where one has it).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "command/live_loop.h"
#include "common/temp_dir.h"
#include "penumbra/command/command_dispatcher.h"

namespace penumbra {
namespace episode_reset_test {
namespace {

using json = nlohmann::json;
using penumbra::testing::LiveLoop;

// what an episode sends besides `step`
enum class Action { kNone, kTwist, kJointTargets };

struct Case {
  std::string name;
  std::string world;  // world file text ("" = the bundled world `file`)
  std::string file;   // bundled world, relative to worlds/
  Action action = Action::kNone;
  int steps = 150;
};

// gtest names a case by its controller type
void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

// one step's qpos and qvel as raw doubles
using Trajectory = std::vector<std::vector<double>>;

// `steps` single steps from now with the case's actions (`variant` changes them, for the
// episodes that only put the controllers in another state); qpos and qvel after each
Trajectory Episode(LiveLoop& live, const Case& c, int steps, int variant = 0) {
  Trajectory out;
  for (int k = 0; k < steps; ++k) {
    if (k == steps / 3 || k == 2 * steps / 3) {
      const double sign = (k == steps / 3 ? 1.0 : -1.0) * (variant == 0 ? 1.0 : -0.5);
      if (c.action == Action::kTwist) {
        live.CallOk({{"cmd", "twist"}, {"vx", 0.3 * std::abs(sign)}, {"yaw_rate", 0.4 * sign}});
      } else if (c.action == Action::kJointTargets) {
        live.CallOk(
            {{"cmd", "joint_targets"}, {"values", {0.2 * sign, 0.1, 0, -2.0, 0, 1.9, 0.785}}});
      }
    }
    live.CallOk({{"cmd", "step"}, {"n", 1}});
    const json s = live.CallOk({{"cmd", "get_state"}});
    std::vector<double> row = s.at("qpos").get<std::vector<double>>();
    const std::vector<double> qvel = s.at("qvel").get<std::vector<double>>();
    row.insert(row.end(), qvel.begin(), qvel.end());
    out.push_back(std::move(row));
  }
  return out;
}

// the first step (of `b` vs `a`) whose qpos/qvel differ in any bit; -1 when none
int FirstDifference(const Trajectory& a, const Trajectory& b) {
  if (a.size() != b.size()) return 0;
  for (size_t k = 0; k < a.size(); ++k) {
    if (a[k].size() != b[k].size() ||
        std::memcmp(a[k].data(), b[k].data(), a[k].size() * sizeof(double)) != 0)
      return static_cast<int>(k);
  }
  return -1;
}

class EpisodeResetTest : public ::testing::TestWithParam<Case> {};

TEST_P(EpisodeResetTest, SameActionsAfterResetGiveTheFirstEpisodeBitForBit) {
  const Case& c = GetParam();
  penumbra::testing::TempDir dir;
  const std::string world = c.world.empty() ? std::string(PENUMBRA_SOURCE_DIR) + "/worlds/" + c.file
                                            : dir.Write("world.yaml", c.world);
  LiveLoop live(world, 1000.0);
  const Trajectory first = Episode(live, c, c.steps);
  // the robot moved: the comparison below is not between two standing-still runs
  EXPECT_NE(first.front(), first.back());
  // episodes after other actions, of lengths that leave the reset at an odd step and at a
  // step off the controllers' update grid
  for (int before : {37, 61}) {
    Episode(live, c, before, 1);
    const json r = live.CallOk({{"cmd", "reset"}});
    EXPECT_GT(r.at("step").get<int64_t>(), 0);  // sim time goes on
    const Trajectory again = Episode(live, c, c.steps);
    EXPECT_EQ(FirstDifference(first, again), -1) << c.name << ": the episode after a reset at step "
                                                 << r.at("step") << " differs from the first one";
  }
}

std::string ArmWorld(const std::string& controller) {
  return std::string(
             "physics: {timestep_sec: 0.002}\n"
             "robots:\n"
             "  - name: arm\n"
             "    file: " PENUMBRA_SOURCE_DIR
             "/worlds/models/arm.xml\n"
             "    controller:\n") +
         controller;
}

const char* kArmServo =
    "      joints: [joint1, joint2, joint3, joint4, joint5, joint6, joint7]\n"
    "      actuators: [actuator1, actuator2, actuator3, actuator4, actuator5, actuator6, "
    "actuator7]\n"
    "      output: torque\n"
    "      kp: [600, 600, 600, 600, 250, 150, 50]\n"
    "      kd: [50, 50, 50, 50, 30, 25, 15]\n"
    "      max_velocity: [2.175, 2.175, 2.175, 2.175, 2.61, 2.61, 2.61]\n"
    "      gravity_compensation: true\n";

INSTANTIATE_TEST_SUITE_P(
    Controllers, EpisodeResetTest,
    ::testing::Values(
        Case{"trot_gait", "", "quadruped.yaml", Action::kTwist},
        Case{"policy", "", "quadruped_policy.yaml", Action::kTwist},
        Case{"waypoint_follower", "", "rover.yaml", Action::kTwist},
        Case{"diff_ik", "", "arm.yaml", Action::kNone},
        Case{"multirotor_pid", "", "quadrotor.yaml", Action::kNone},
        Case{"joint_pd",
             ArmWorld(std::string("      type: joint_pd\n") + kArmServo +
                      "      commands:\n"
                      "        - {t: 0.1, q: [0.5, 0.3, -0.4, -1.5, 0.6, 2.2, 0.0]}\n"),
             "", Action::kJointTargets},
        Case{"keyframe_playback",
             ArmWorld(std::string("      type: keyframe_playback\n") + kArmServo +
                      "      frames:\n"
                      "        - {t: 0.1, key: reach}\n"
                      "        - {t: 0.3, key: rest}\n"),
             "", Action::kNone}),
    [](const ::testing::TestParamInfo<Case>& info) { return info.param.name; });

}  // namespace
}  // namespace episode_reset_test
}  // namespace penumbra
