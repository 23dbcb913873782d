#pragma once
// a paused (lockstep) live loop over a world file, driven by a dispatcher: what the command
// tests run requests against (Session -> RunControl -> PhysicsSource -> SimLoop, as
// `penumbra run --lockstep` without sinks).

#include <gtest/gtest.h>

#include <functional>
#include <memory>
#include <string>

#include "penumbra/command/command_dispatcher.h"
#include "penumbra/command/run_control.h"
#include "penumbra/command/run_description.h"
#include "penumbra/physics/physics_source.h"
#include "penumbra/pipeline/sim_loop.h"
#include "penumbra/session/session.h"
#include "penumbra/world/world_config.h"

namespace penumbra::testing {

class LiveLoop {
 public:
  /// loads `world_file` (no renderer) and starts the loop paused; it ends at `end_time_sec` of
  /// sim time or on `stop`. `add_sinks` (optional) adds sinks to the loop before it starts;
  /// they must outlive the LiveLoop. `build_renderer`: the session builds its renderer (for
  /// camera sinks).
  LiveLoop(const std::string& world_file, double end_time_sec,
           const std::function<void(Session&, SimLoop&)>& add_sinks = {},
           bool build_renderer = false) {
    SessionOptions so;
    so.build_renderer = build_renderer;
    session_ = std::make_unique<Session>(LoadWorldFile(world_file), so);
    RunControlOptions co;
    co.start_paused = true;
    control_ = std::make_unique<RunControl>(&session_->sim(), co);
    dispatcher_ =
        std::make_unique<CommandDispatcher>(*session_, session_->world(), control_.get(),
                                            DescribeRun(*session_, session_->world()), true);
    PhysicsSourceOptions po;
    po.before_step = [this](Simulation& sim) { return control_->BeforeStep(sim); };
    source_ = std::make_unique<PhysicsSource>(&session_->sim(), po);
    SimLoopOptions lo;
    lo.end_time_sec = end_time_sec;
    lo.stop_request = control_->stop_flag();
    loop_ = std::make_unique<SimLoop>(source_.get(), lo);
    loop_->AddSink(control_.get());
    if (add_sinks) add_sinks(*session_, *loop_);
    loop_->Start();
  }
  ~LiveLoop() {
    control_->RequestStop();
    loop_->Wait();
  }
  LiveLoop(const LiveLoop&) = delete;
  LiveLoop& operator=(const LiveLoop&) = delete;

  /// the dispatcher's reply to `request` (JSON form of docs/zmq-protocol.md), waiting for it.
  nlohmann::json Call(const nlohmann::json& request) { return dispatcher_->Call(request); }
  /// Call for a request that must succeed: a reply without `ok` true fails the test (gtest
  /// EXPECT, naming the request and the reply); returns the reply.
  nlohmann::json CallOk(const nlohmann::json& request) {
    nlohmann::json r = Call(request);
    EXPECT_TRUE(r.at("ok").get<bool>()) << request.dump() << " -> " << r.dump();
    return r;
  }
  /// sends `stop` and waits for the loop's end.
  LoopFinish Stop() {
    Call({{"cmd", "stop"}});
    return loop_->Wait();
  }

 private:
  std::unique_ptr<Session> session_;
  std::unique_ptr<RunControl> control_;
  std::unique_ptr<CommandDispatcher> dispatcher_;
  std::unique_ptr<PhysicsSource> source_;
  std::unique_ptr<SimLoop> loop_;
};

}  // namespace penumbra::testing
