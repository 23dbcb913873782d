#pragma once
// RunControl: the loop-thread side of the command layer. a live run (run/runner.cc with
// bridges) steps its Simulation through a PhysicsSource whose before_step hook is
// RunControl::BeforeStep, so everything that changes the simulation happens there, on the
// loop thread, at a step boundary:
//
//   BeforeStep (before physics step s -> s + 1; every sink has the snapshot of step s):
//     1. a step request whose steps are all taken completes: the drains run (every camera
//        frame and sensor sample of steps <= s reaches the bridges), then its reply is sent;
//     2. queued work runs in arrival order: actions (commands) and step requests; a step
//        request becomes active and the queue waits behind it until it completes;
//     3. an active step request takes the step; a running (not paused) run paces the step to
//        wall-clock time (realtime factor) and takes it; a paused run waits for work.
//
// determinism: actions run only at step boundaries, in arrival order, and a paused run moves
// only by step requests, so a lockstep client that sends the same requests gets the same
// trajectory bit for bit, whatever the wall-clock timing.
//
// threads: Submit, RequestSteps, RequestStop, SetRealtimeFactor are thread-safe (any transport
// thread). BeforeStep and the Sink methods run on the loop thread. `done` callbacks run on the
// loop thread (or on the caller's thread for requests refused at once): they must be quick and
// must not call back into RunControl synchronously except Submit/RequestSteps.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <vector>

#include "penumbra/physics/simulation.h"
#include "penumbra/pipeline/sink.h"

namespace penumbra {

/// settings of a RunControl.
struct RunControlOptions {
  /// the run starts paused (lockstep: it advances only by step requests).
  bool start_paused = false;
  /// sim seconds per wall-clock second while running; 0 = as fast as possible.
  double realtime_factor = 0;
  /// an outside stop request (SIGINT; null = none), polled at least every 50 ms while waiting.
  const std::atomic<int>* external_stop = nullptr;
};

/// queues commands for the loop thread and gates its steps (see the file comment).
class RunControl : public Sink {
 public:
  /// SinkStage::kRunControl: after the outputs and recorders: a step reply follows its outputs.
  SinkStage stage() const override { return SinkStage::kRunControl; }
  /// work run on the loop thread at a step boundary with the simulation; returns the reply's
  /// fields. may throw CommandError (becomes an error reply) or anything else (a `failed` reply).
  using Action = std::function<nlohmann::json(Simulation& sim)>;
  /// receives the reply fields (`ok` true) or an error reply object (`ok` false, `error`).
  using Done = std::function<void(nlohmann::json reply)>;

  /// `sim` must outlive the control. @throws Error for a negative realtime factor.
  RunControl(Simulation* sim, RunControlOptions options = {});
  ~RunControl() override;

  /// PhysicsSourceOptions::before_step (see the file comment); false = stop the run.
  bool BeforeStep(Simulation& sim);
  /// the flag the SimLoop must use as its stop request (SimLoopOptions::stop_request): set by
  /// RequestStop, by the outside stop request, and when the loop ends.
  const std::atomic<int>* stop_flag() const { return &stop_; }

  /// a function the loop thread calls before completing a step request or pausing (e.g.
  /// CameraSink::Drain, SensorSink::Drain); before the loop starts.
  void AddDrain(std::function<void()> drain);

  /// queues `action` for the next step boundary; `done` gets its result. after the run ended,
  /// `done` gets a run_ended error at once.
  void Submit(Action action, Done done);
  /// queues a request for `n` >= 1 steps; `done` gets {"step", "time_sec", "ended"} plus, with
  /// `with_state`, the fields of StateJson, once the steps are taken and drained (or when the
  /// run ends before: "ended": true). a request that becomes due while the run is not paused
  /// gets a conflict error.
  void RequestSteps(int64_t n, bool with_state, Done done);
  /// ends the run at the next step boundary (as SIGINT does). thread-safe.
  void RequestStop();
  /// changes the realtime factor (>= 0; 0 = as fast as possible) from the next step on.
  void SetRealtimeFactor(double factor);
  double realtime_factor() const { return factor_.load(); }
  /// pauses or resumes at the next step boundary (Submit of an action that does it; a pause
  /// drains first, so no frame of the running phase arrives after the reply).
  void SetPaused(bool paused, Done done);

  /// whether the run is paused (as of the last boundary), has ended.
  bool paused() const { return paused_.load(); }
  bool ended() const { return ended_.load(); }
  /// whether the run takes no further step: a stop was requested (`stop`, the outside stop
  /// request) or it has ended (any thread).
  bool stopping() const {
    return stop_queued_.load() || stop_.load() != 0 || ended_.load() ||
           (options_.external_stop && options_.external_stop->load() != 0);
  }
  /// a `stop` command was queued (it ends the run at its boundary): from now on stopping()
  /// is true, so requests that arrive after it are refused where a stop matters (thread-safe).
  void NoteStopQueued() { stop_queued_.store(true); }
  /// the step and sim time of the last step boundary the loop thread passed (any thread).
  int64_t boundary_step() const { return boundary_step_.load(); }
  double boundary_time_sec() const { return boundary_time_.load(); }
  /// the simulation's state when the loop started (reset target).
  const SimState& initial_state() const { return initial_; }

  /// {"step", "time_sec", "qpos", "qvel", "act", "ctrl", "mocap_pos", "mocap_quat",
  /// "sensordata", "paused"} of `sim` now (sensordata: the last step's; MuJoCo's order).
  nlohmann::json StateJson(const Simulation& sim) const;

  // Sink: records the initial state (and, paused, waits for the first step request; see the
  // file comment), completes pending requests at the end. add it after the output sinks.
  void OnStart(const LoopStart& start) override;
  SnapshotContent Wants(int64_t, double) override { return SnapshotContent::kNone; }
  void OnSnapshot(const std::shared_ptr<const WorldSnapshot>&) override {}
  /// completes an active step request ("ended": true) and fails queued work that was not carried
  /// out with a `stopping` error.
  void OnFinish(const LoopFinish& finish) override;

 private:
  struct Work {
    Action action;      // set for an action
    int64_t steps = 0;  // > 0 for a step request
    bool with_state = false;
    Done done;
  };
  using Clock = std::chrono::steady_clock;

  // the body of BeforeStep (at_start: from OnStart, before the first snapshot)
  bool Gate(Simulation& sim, bool at_start);
  void RunDrains();
  void CompleteSteps(Simulation& sim, bool ended);
  void Reanchor(const Simulation& sim);

  Simulation* sim_;
  RunControlOptions options_;
  std::vector<std::function<void()>> drains_;
  SimState initial_;

  std::mutex mu_;
  std::condition_variable cv_;
  std::deque<Work> queue_;  // guarded by mu_
  std::atomic<bool> has_work_{false};
  std::atomic<int> stop_{0};
  std::atomic<bool> paused_{false};
  std::atomic<bool> ended_{false};
  std::atomic<bool> stop_queued_{false};
  std::atomic<double> factor_{0};
  std::atomic<bool> factor_changed_{false};
  std::atomic<int64_t> boundary_step_{0};
  std::atomic<double> boundary_time_{0};

  // loop thread
  std::optional<Work> active_;  // the step request being taken
  int64_t remaining_ = 0;
  bool anchored_ = false;
  Clock::time_point anchor_wall_;
  int64_t anchor_step_ = 0;
};

}  // namespace penumbra
