#pragma once
// the bridges of one live run and what they share: the RunControl, the CommandDispatcher and
// the model description, wired into a run's outputs and loop. run/runner.cc builds one when
// RunOptions::bridges is not empty:
//
//   RunOutputs outputs(...);
//   BridgeSet bridges(session, world, outputs, options, factories);   // makes the bridges
//   bridges.Configure(&physics_options, &loop_options);  // before_step gate, stop flag
//   ... PhysicsSource, SimLoop ...
//   outputs.AddTo(&loop); (recorder); bridges.AddTo(&loop); loop.AddSink(&manifest);
//
// camera frames and sensor samples reach every bridge (CameraSink::set_on_frame,
// SensorSink::set_on_sample); the RunControl drains the camera and sensor threads before a
// step reply (command/run_bridge.h states the guarantee).
//
// live view at real-time pacing (realtime factor > 0, e.g. `penumbra view`, `run --realtime
// --viewer`): before every step the loop waits until every camera frame captured so far is
// rendered and handed to the bridges (CameraSink::Drain), and only then applies the queued
// commands and steps. no frame captured before a command is still waiting for the renderer
// when the command applies, so a teleop key shows on the next rendered frame (not behind one
// or two stale ones); every captured frame is still rendered and written. running as fast as
// possible (factor 0) keeps the render queue (RunOutputsOptions::render_queue) for throughput.

#include <atomic>
#include <memory>
#include <nlohmann/json.hpp>
#include <vector>

#include "penumbra/command/command_dispatcher.h"
#include "penumbra/command/run_bridge.h"
#include "penumbra/command/run_control.h"
#include "penumbra/physics/physics_source.h"
#include "penumbra/pipeline/sim_loop.h"
#include "penumbra/sinks/run/run_outputs.h"

namespace penumbra {

/// how the bridges drive the run.
struct BridgeSetOptions {
  /// start paused: the run advances only by `step` requests (--lockstep).
  bool lockstep = false;
  /// sim seconds per wall-clock second while running free; 0 = as fast as possible
  /// (--realtime: 1).
  double realtime_factor = 0;
  /// the run's outside stop request (SIGINT; null = none).
  const std::atomic<int>* external_stop = nullptr;
  /// the run's live effects and recorder for set_adversity, set_effect, start_recording and
  /// stop_recording (null: those reply not_available); outlives the set.
  LiveControl* live = nullptr;
};

/// the bridges of a run (see the file comment). neither copied nor moved.
class BridgeSet {
 public:
  /// describes the run, makes the RunControl and the dispatcher, calls every factory and
  /// connects the outputs' camera frames and sensor samples to the bridges. `session`,
  /// `world` and `outputs` must outlive the set.
  /// @throws what a factory throws (ConfigError, Error).
  BridgeSet(Session& session, const WorldConfig& world, RunOutputs& outputs,
            BridgeSetOptions options, const std::vector<RunBridgeFactory>& factories);
  ~BridgeSet();
  BridgeSet(const BridgeSet&) = delete;
  BridgeSet& operator=(const BridgeSet&) = delete;

  /// sets the physics source's before_step to the RunControl gate (after draining the camera
  /// thread while the realtime factor is > 0: see the file comment), turns its own pacing off
  /// (the RunControl paces) and makes the loop's stop request the RunControl's flag.
  void Configure(PhysicsSourceOptions* physics, SimLoopOptions* loop);
  /// adds the RunControl, then every bridge, to `loop` (their stages, kRunControl and kBridges,
  /// put them after the outputs and recorders and before the manifest).
  void AddTo(SimLoop* loop);

  RunControl& control() { return *control_; }
  CommandDispatcher& dispatcher() { return *dispatcher_; }
  const nlohmann::json& model_info() const { return model_info_; }

 private:
  nlohmann::json model_info_;
  std::unique_ptr<RunControl> control_;
  std::unique_ptr<CommandDispatcher> dispatcher_;
  std::vector<std::unique_ptr<RunBridge>> bridges_;
  CameraSink* cameras_ = nullptr;
};

}  // namespace penumbra
