#pragma once
// the live controls of a running world, as the bridges (ZeroMQ, ROS) and the browser viewer
// reach them through their shared command dispatcher: the adverse
// conditions (live/live_effects.h) and run-log recording (live/live_recorder.h). a run
// (run/runner.h RunOptions::on_live) hands its LiveControl to the caller once it is set up.
//
// in a SimLoop: effects() is a kLiveChanges sink (changes apply before any other sink sees the
// step) and recorder() a kRecording sink (after the cameras and sensors, so their records reach
// it before it closes): their stages (pipeline/sink.h SinkStage) say where, whatever the order
// of AddSink calls. every change applied is recorded
// as a "live" event in the active live recording and in the run's own log (RecordChangesTo).

#include <cstdint>
#include <filesystem>
#include <string>

#include "penumbra/live/live_effects.h"
#include "penumbra/live/live_recorder.h"
#include "penumbra/pipeline/sim_loop.h"
#include "penumbra/runlog/run_log_writer.h"
#include "penumbra/session/session.h"

namespace penumbra {

/// the live controls of one Session's run. calls on effects() and recorder() are thread-safe
/// (see their headers); the object lives as long as the run (RunWorld) and must not be used
/// after it returns.
class LiveControl {
 public:
  /// `session` must outlive this object; build it before the loop starts. `command_line`
  /// goes into the headers of the logs recorder() writes; `output_folder` is the run's output
  /// folder, the only place recorder() writes (core/output_path_policy.h).
  LiveControl(Session& session, const std::string& command_line,
              const std::filesystem::path& output_folder);
  LiveControl(const LiveControl&) = delete;
  LiveControl& operator=(const LiveControl&) = delete;

  LiveEffects& effects() { return effects_; }
  /// the step the loop last reached, -1 before the first (LiveEffects::step; thread-safe).
  int64_t step() const { return effects_.step(); }
  LiveRecorder& recorder() { return recorder_; }

  /// every change applied is also recorded as a "live" event in `writer` (the run's own
  /// --record log; may be null). call before the loop starts; `writer` must outlive the loop.
  void RecordChangesTo(RunLogWriter* writer) { run_log_ = writer; }

  /// a command a bridge carried out that changes the simulation (set_ctrl, twist, ...; the
  /// request without its id) at the step boundary after `step` (loop thread): recorded as a
  /// "command" event at `step` in the run's own log and in an active live recording, so that
  /// `replay --resimulate` knows the run was driven from outside (docs/run-log.md). a write
  /// error is logged, not thrown (the command was carried out).
  void RecordCommand(int64_t step, double time_sec, const nlohmann::json& command);

  /// adds effects() and recorder() to `loop` (their stages order them among its sinks).
  void AddTo(SimLoop* loop) {
    loop->AddSink(&effects_);
    loop->AddSink(&recorder_);
  }

 private:
  LiveEffects effects_;
  LiveRecorder recorder_;
  RunLogWriter* run_log_ = nullptr;
};

}  // namespace penumbra
