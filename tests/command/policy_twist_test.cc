// velocity commands reach the policy controller the way they reach trot_gait: the run
// description lists `twist` and `waypoints` for it, and the dispatcher's `twist` request (what
// the ZeroMQ and ROS bridges, the viewer's teleop and the navigator send) becomes the command
// its velocity_command observation reads at the next policy update.
#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "common/temp_dir.h"
#include "penumbra/command/command_dispatcher.h"
#include "penumbra/command/run_control.h"
#include "penumbra/command/run_description.h"
#include "penumbra/control/policy_controller.h"
#include "penumbra/physics/physics_source.h"
#include "penumbra/pipeline/sim_loop.h"
#include "penumbra/session/session.h"

namespace penumbra {
namespace {

using json = nlohmann::json;

TEST(PolicyTwistCommand, TwistRequestsReachThePolicysCommandTerm) {
  penumbra::testing::TempDir dir;
  const std::string world =
      dir.Write("world.yaml",
                "physics: {timestep_sec: 0.005}\n"
                "robots:\n"
                "  - name: dog\n"
                "    file: " PENUMBRA_SOURCE_DIR
                "/worlds/models/quadruped.xml\n"
                "    controller:\n"
                "      type: policy\n"
                "      model: " PENUMBRA_SOURCE_DIR
                "/worlds/policies/stand_48x12.onnx\n"
                "      preset: isaac_lab\n"
                "      base_body: trunk\n"
                "      joints: [FR_hip, FR_thigh, FR_calf, FL_hip, FL_thigh, FL_calf,\n"
                "               RR_hip, RR_thigh, RR_calf, RL_hip, RL_thigh, RL_calf]\n"
                "      default_joint_pos: {'.*_thigh': 0.9, '.*_calf': -1.8}\n"
                "      action: {scale: 0.25, kp: 80, kd: 2}\n"
                "      commands: [{t: 0, vx: 0.1}]\n");
  SessionOptions so;
  so.build_renderer = false;
  Session session(LoadWorldFile(world), so);
  const json description = DescribeRun(session, session.world());
  ASSERT_EQ(description.at("controllers").size(), 1u);
  EXPECT_EQ(description["controllers"][0].at("type"), "policy");
  EXPECT_EQ(description["controllers"][0].at("commands"), json({"twist", "waypoints"}));

  auto* policy = dynamic_cast<PolicyController*>(&session.sim().mutable_controller(0));
  ASSERT_NE(policy, nullptr);
  RunControlOptions co;
  co.start_paused = true;
  RunControl control(&session.sim(), co);
  CommandDispatcher dispatcher(session, session.world(), &control, description, true);
  PhysicsSourceOptions po;
  po.before_step = [&control](Simulation& sim) { return control.BeforeStep(sim); };
  PhysicsSource source(&session.sim(), po);
  SimLoopOptions lo;
  lo.end_time_sec = 10.0;
  lo.stop_request = control.stop_flag();
  SimLoop loop(&source, lo);
  loop.AddSink(&control);
  loop.Start();

  // the script first: vx 0.1 (isaac_lab: velocity_command at 9 .. 11)
  ASSERT_TRUE(dispatcher.Call({{"cmd", "step"}, {"n", 4}}).at("ok").get<bool>());
  EXPECT_FLOAT_EQ(policy->last_observation()[9], 0.1f);
  // a twist request overrides it from the next policy update (every 4 steps of 5 ms)
  const json r = dispatcher.Call({{"cmd", "twist"}, {"vx", 0.4}, {"vy", -0.2}, {"yaw_rate", 0.3}});
  ASSERT_TRUE(r.at("ok").get<bool>()) << r.dump();
  EXPECT_EQ(r.at("robot"), "dog");
  ASSERT_TRUE(dispatcher.Call({{"cmd", "step"}, {"n", 4}}).at("ok").get<bool>());
  EXPECT_FLOAT_EQ(policy->last_observation()[9], 0.4f);
  EXPECT_FLOAT_EQ(policy->last_observation()[10], -0.2f);
  EXPECT_FLOAT_EQ(policy->last_observation()[11], 0.3f);
  // clearing returns to the script
  ASSERT_TRUE(dispatcher.Call({{"cmd", "twist"}, {"clear", true}}).at("ok").get<bool>());
  ASSERT_TRUE(dispatcher.Call({{"cmd", "step"}, {"n", 4}}).at("ok").get<bool>());
  EXPECT_FLOAT_EQ(policy->last_observation()[9], 0.1f);
  EXPECT_FLOAT_EQ(policy->last_observation()[11], 0.0f);
  // a route: pure pursuit towards a point ahead of the robot
  ASSERT_TRUE(dispatcher.Call({{"cmd", "waypoints"}, {"points", json::array({{3.0, 0.0}})}})
                  .at("ok")
                  .get<bool>());
  ASSERT_TRUE(dispatcher.Call({{"cmd", "step"}, {"n", 4}}).at("ok").get<bool>());
  EXPECT_GT(policy->last_observation()[9], 0.1f);
  control.RequestStop();
  loop.Wait();
}

}  // namespace
}  // namespace penumbra
