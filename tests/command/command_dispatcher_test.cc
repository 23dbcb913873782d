// the command layer (command/command_dispatcher.h, command/run_control.h) on a live loop: every
// kind of bad request gets an error reply naming its field and the next request works;
// commands apply at step boundaries, so two runs given the same requests are bit-identical.
#include "penumbra/command/command_dispatcher.h"

#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "command/live_loop.h"
#include "common/temp_dir.h"
#include "penumbra/pipeline/sim_loop.h"

namespace penumbra {
namespace {

using json = nlohmann::json;
using penumbra::testing::LiveLoop;

std::string Pendulum() {
  return "<mujoco>\n"
         "  <worldbody><body name=\"arm\" pos=\"0 0 1\">\n"
         "    <joint name=\"hinge\" type=\"hinge\" axis=\"0 1 0\" damping=\"0.1\"/>\n"
         "    <geom type=\"capsule\" fromto=\"0 0 0 0 0 -0.5\" size=\"0.02\"/>\n"
         "  </body>\n"
         "  <body name=\"target\" mocap=\"true\" pos=\"1 0 1\"><geom type=\"sphere\" "
         "size=\"0.05\" contype=\"0\" conaffinity=\"0\"/></body></worldbody>\n"
         "  <actuator><motor name=\"m\" joint=\"hinge\"/></actuator>\n"
         "  <keyframe><key name=\"home\" qpos=\"0.7\" mpos=\"1 0 1\" mquat=\"1 0 0 0\"/>"
         "</keyframe>\n"
         "</mujoco>\n";
}

class CommandDispatcherTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_.Write("pendulum.xml", Pendulum());
    world_ = dir_.Write("world.yaml", "seed: 4\nmodels:\n  - {name: a, file: pendulum.xml}\n");
  }
  penumbra::testing::TempDir dir_;
  std::string world_;
};

void ExpectError(LiveLoop& live, const json& request, const std::string& code, const json& field) {
  const json r = live.Call(request);
  ASSERT_FALSE(r.at("ok").get<bool>()) << r.dump();
  EXPECT_EQ(r.at("error").at("code"), code) << r.dump();
  EXPECT_EQ(r.at("error").at("field"), field) << r.dump();
  EXPECT_FALSE(r.at("error").at("message").get<std::string>().empty());
  // the next valid request works
  EXPECT_TRUE(live.Call({{"cmd", "get_state"}}).at("ok").get<bool>());
}

TEST_F(CommandDispatcherTest, BadRequestsGetErrorsNamingTheField) {
  LiveLoop live(world_, 1.0);
  ExpectError(live, json::array({1, 2}), "malformed", nullptr);
  ExpectError(live, {{"n", 1}}, "malformed", "cmd");
  ExpectError(live, {{"cmd", 5}}, "malformed", "cmd");
  ExpectError(live, {{"cmd", "jump"}}, "unknown_command", "cmd");
  ExpectError(live, {{"cmd", "step"}, {"n", "many"}}, "bad_field", "n");
  ExpectError(live, {{"cmd", "step"}, {"n", -3}}, "bad_field", "n");
  ExpectError(live, {{"cmd", "step"}, {"n", 2.5}}, "bad_field", "n");
  ExpectError(live, {{"cmd", "step"}, {"count", 2}}, "unknown_field", "count");
  ExpectError(live, {{"cmd", "set_ctrl"}}, "missing_field", "ctrl");
  ExpectError(live, {{"cmd", "set_ctrl"}, {"ctrl", "x"}}, "bad_field", "ctrl");
  ExpectError(live, {{"cmd", "set_ctrl"}, {"ctrl", {1.0, 2.0}}}, "bad_field", "ctrl");
  ExpectError(live, {{"cmd", "set_ctrl"}, {"ctrl", {"x"}}}, "bad_field", "ctrl[0]");
  ExpectError(live, {{"cmd", "set_ctrl"}, {"ctrl", {{"b/m", 1.0}}}}, "bad_field", "ctrl.b/m");
  ExpectError(live, {{"cmd", "twist"}, {"vx", 1.0}}, "not_available", nullptr);
  ExpectError(live, {{"cmd", "set_mocap"}, {"body", "a/arm"}, {"xyz", {0, 0, 0}}}, "bad_field",
              "body");
  ExpectError(live, {{"cmd", "set_mocap"}, {"body", "a/target"}, {"xyz", {0, 0}}}, "bad_field",
              "xyz");
  ExpectError(
      live,
      {{"cmd", "set_mocap"}, {"body", "a/target"}, {"xyz", {0, 0, 1}}, {"qwxyz", {0, 0, 0, 0}}},
      "bad_field", "qwxyz");
  ExpectError(live, {{"cmd", "reset"}, {"keyframe", "away"}}, "bad_field", "keyframe");
  ExpectError(live, {{"cmd", "reset"}, {"seed", 9}}, "bad_field", "seed");
  ExpectError(live, {{"cmd", "hello"}, {"protocol", 7}}, "version_mismatch", "protocol");
  ExpectError(live, {{"cmd", "set_realtime_factor"}, {"factor", -1}}, "bad_field", "factor");
  ExpectError(live, {{"cmd", "start_recording"}, {"path", "x.plog"}}, "not_available", nullptr);
  // the id comes back, also on errors
  const json r = live.Call({{"cmd", "jump"}, {"id", "abc"}});
  EXPECT_EQ(r.at("id"), "abc");
  EXPECT_EQ(live.Call({{"cmd", "hello"}, {"protocol", 1}, {"id", 3}}).at("id"), 3);
  EXPECT_EQ(live.Stop().reason, LoopEndReason::kStopRequested);
}

// the same requests give the same trajectory, bit for bit
json Drive(const std::string& world) {
  LiveLoop live(world, 1.0);
  EXPECT_TRUE(live.Call({{"cmd", "set_ctrl"}, {"ctrl", {0.3}}}).at("ok").get<bool>());
  json r = live.Call({{"cmd", "step"}, {"n", 17}});
  EXPECT_EQ(r.at("step"), 17) << r.dump();
  EXPECT_FALSE(r.at("ended").get<bool>());
  EXPECT_TRUE(live.Call({{"cmd", "set_ctrl"}, {"ctrl", {{"a/m", -0.2}}}}).at("ok").get<bool>());
  EXPECT_TRUE(live.Call({{"cmd", "set_mocap"}, {"body", "a/target"}, {"xyz", {0.5, 0.1, 1.2}}})
                  .at("ok")
                  .get<bool>());
  r = live.Call({{"cmd", "step"}, {"n", 23}, {"state", true}});
  EXPECT_EQ(r.at("step"), 40);
  EXPECT_EQ(r.at("ctrl"), json({-0.2}));
  EXPECT_EQ(r.at("mocap_pos"), json({0.5, 0.1, 1.2}));
  live.Stop();
  return r;
}

TEST_F(CommandDispatcherTest, SameRequestsGiveTheSameTrajectory) {
  const json a = Drive(world_);
  const json b = Drive(world_);
  EXPECT_EQ(a.at("qpos"), b.at("qpos"));
  EXPECT_EQ(a.at("qvel"), b.at("qvel"));
  EXPECT_NE(a.at("qpos").at(0).get<double>(), 0.0);  // the motor moved the pendulum
}

TEST_F(CommandDispatcherTest, ResetRestoresTheStartOrAKeyframe) {
  LiveLoop live(world_, 1.0);
  const json s0 = live.Call({{"cmd", "get_state"}});
  live.Call({{"cmd", "set_ctrl"}, {"ctrl", {1.0}}});
  live.Call({{"cmd", "step"}, {"n", 50}});
  const json moved = live.Call({{"cmd", "get_state"}});
  EXPECT_NE(moved.at("qpos"), s0.at("qpos"));
  const json r = live.Call({{"cmd", "reset"}});
  ASSERT_TRUE(r.at("ok").get<bool>()) << r.dump();
  EXPECT_EQ(r.at("step"), 50);  // sim time goes on
  const json s1 = live.Call({{"cmd", "get_state"}});
  EXPECT_EQ(s1.at("qpos"), s0.at("qpos"));
  EXPECT_EQ(s1.at("qvel"), s0.at("qvel"));
  EXPECT_EQ(s1.at("ctrl"), s0.at("ctrl"));
  ASSERT_TRUE(live.Call({{"cmd", "reset"}, {"keyframe", "a/home"}}).at("ok").get<bool>());
  EXPECT_EQ(live.Call({{"cmd", "get_state"}}).at("qpos"), json({0.7}));
  live.Stop();
}

TEST_F(CommandDispatcherTest, StepNeedsAPausedRunAndEndsWithTheRun) {
  LiveLoop live(world_, 1.0);
  // running free at 1 % of real time: 0.2 s of wall time per 2 ms step
  EXPECT_EQ(live.Call({{"cmd", "set_realtime_factor"}, {"factor", 0.01}}).at("factor"), 0.01);
  EXPECT_EQ(live.Call({{"cmd", "resume"}}).at("paused"), false);
  const json r = live.Call({{"cmd", "step"}});
  EXPECT_EQ(r.at("error").at("code"), "conflict") << r.dump();
  EXPECT_EQ(live.Call({{"cmd", "pause"}}).at("paused"), true);
  // the run ends at 1 s (500 steps): a step request past it ends with it
  const json end = live.Call({{"cmd", "step"}, {"n", 1000000}});
  EXPECT_TRUE(end.at("ended").get<bool>()) << end.dump();
  EXPECT_EQ(end.at("step"), 500);
  const json after = live.Call({{"cmd", "get_state"}});
  EXPECT_EQ(after.at("error").at("code"), "run_ended") << after.dump();
}

// once a `stop` is queued, a start_recording would get no step; it is refused with
// `stopping` (before anything else is checked), also when it arrives while the run finishes
TEST_F(CommandDispatcherTest, StartRecordingAfterAStopIsRefusedWithStopping) {
  LiveLoop live(world_, 1.0);
  EXPECT_TRUE(live.Call({{"cmd", "step"}, {"n", 2}}).at("ok").get<bool>());
  EXPECT_TRUE(live.Call({{"cmd", "stop"}}).at("ok").get<bool>());
  const json r = live.Call({{"cmd", "start_recording"}, {"path", "late.plog"}, {"id", 9}});
  ASSERT_FALSE(r.at("ok").get<bool>()) << r.dump();
  EXPECT_EQ(r.at("error").at("code"), "stopping") << r.dump();
  EXPECT_EQ(r.at("id"), 9);
}

// waypoints from a client are finite and inside the scene's bounds (scene/scene_limits.h
// kMaxPositionM): 1e300 used to be accepted
TEST_F(CommandDispatcherTest, WaypointsOutsideTheSceneAreRefusedNamingThePoint) {
  const std::string world = dir_.Write("rover.yaml", std::string("seed: 1\n"
                                                                 "robots:\n"
                                                                 "  - name: rover\n"
                                                                 "    file: ") +
                                                         PENUMBRA_SOURCE_DIR +
                                                         "/worlds/models/rover.xml\n"
                                                         "    controller:\n"
                                                         "      type: waypoint_follower\n"
                                                         "      base_body: chassis\n"
                                                         "      left_actuator: left_wheel\n"
                                                         "      right_actuator: right_wheel\n"
                                                         "      wheel_radius_m: 0.05\n"
                                                         "      track_width_m: 0.3\n"
                                                         "      speed_m_s: 0.5\n"
                                                         "      waypoints: [[3.0, 0.0]]\n");
  LiveLoop live(world, 1.0);
  const json far = {{"cmd", "waypoints"}, {"points", json::array({{1.0, 2.0}, {1e300, 0.0}})}};
  const json r = live.Call(far);
  ASSERT_FALSE(r.at("ok").get<bool>()) << r.dump();
  EXPECT_EQ(r.at("error").at("code"), "bad_field") << r.dump();
  EXPECT_EQ(r.at("error").at("field"), "points[1][0]") << r.dump();
  EXPECT_NE(r.at("error").at("message").get<std::string>().find("expected a coordinate in "
                                                                "[-100000, 100000] m"),
            std::string::npos)
      << r.dump();
  ExpectError(live, {{"cmd", "waypoints"}, {"points", json::array({{0.0, -2e5}})}}, "bad_field",
              "points[0][1]");
  EXPECT_TRUE(live.Call({{"cmd", "waypoints"}, {"points", json::array({{1e5, -1e5}})}})
                  .at("ok")
                  .get<bool>());
  live.Stop();
}

}  // namespace
}  // namespace penumbra
