#pragma once
// a consumer of the snapshots a SimLoop (pipeline/sim_loop.h) takes from its source: cameras,
// sensors, the trajectory file, the run manifest; later recorders, bridges, viewers.
//
// order: every sink declares its stage (SinkStage, stage()); a SimLoop calls its sinks stage by
// stage in the order of SinkStage, and sinks of one stage in registration order. the order of
// AddSink calls therefore says nothing about which sink sees a step first.
//
// threading: a SimLoop calls every method of a sink on its loop thread (the thread that
// advances the source), in this order: OnStart once; then for each step Wants and, when a
// snapshot is taken at that step, OnSnapshot; then OnFinish once. the loop waits for each
// call, so a sink must be quick: work that takes long (rendering, ray tracing, encoding,
// writing files) belongs on the sink's own threads, fed from OnSnapshot (the snapshot is
// immutable and may be kept), and those threads report their errors through
// LoopStart::report_error. OnFinish waits for that work to end.

#include <cstdint>
#include <exception>
#include <functional>
#include <memory>

#include "penumbra/pipeline/source.h"
#include "penumbra/scene/world_snapshot.h"

namespace penumbra {

/// what a sink learns when the loop starts.
struct LoopStart {
  int64_t step = 0;         ///< the source's position
  double time_sec = 0;      ///< the source's time, s
  double end_time_sec = 0;  ///< the loop stops at the first step at or after this time
  /// records an error from any thread (first one wins) and makes the loop stop at the next
  /// step boundary; the run then reports the first error. never null while the loop runs.
  std::function<void(std::exception_ptr)> report_error;
};

/// why a loop ended.
enum class LoopEndReason {
  kEndTime,        ///< the source reached LoopStart::end_time_sec
  kSourceEnded,    ///< the source had no further step (Source::Advance returned false)
  kStopRequested,  ///< the stop request was set (SIGINT/SIGTERM)
  kError,          ///< an error was recorded (source, sink, or a sink's thread)
};

/// how a loop ended, given to every sink's OnFinish and returned by SimLoop::Wait.
struct LoopFinish {
  LoopEndReason reason = LoopEndReason::kEndTime;
  int64_t step = 0;     ///< the source's last position
  double time_sec = 0;  ///< the source's time at its last position, s
  /// the first error of the run, or null: in OnFinish, the one recorded so far (including
  /// errors thrown by the OnFinish of sinks registered earlier); from SimLoop::Wait, the final
  /// one.
  std::exception_ptr error;
};

/// where a sink runs in a SimLoop: the loop calls OnStart, Wants, OnSnapshot and OnFinish of
/// its sinks stage by stage in this order (registration order within a stage).
enum class SinkStage {
  /// changes to the world a step shows (live effects, live/live_effects.h): before any
  /// other sink sees the step, so a change applies to every output of the step alike.
  kLiveChanges = 0,
  /// the outputs of a step: cameras, sensors, trajectory, metrics, falls, progress (default).
  kOutputs = 1,
  /// run-log recorders: after the outputs, so that a step's camera and sensor records reach
  /// the log before it closes in OnFinish.
  kRecording = 2,
  /// the step gate of a live run (command/run_control.h): after the outputs and recorders, so
  /// that a step reply follows the step's outputs.
  kRunControl = 3,
  /// middleware bridges and viewers (command/run_bridge.h), after the run control.
  kBridges = 4,
  /// run.json (output/manifest_sink.h): last, so that every other sink finished when it is
  /// written.
  kManifest = 5,
};

/// the stage's name ("live_changes", "outputs", ...), for messages and tests.
const char* SinkStageName(SinkStage stage);

/// receives snapshots from a SimLoop (order and threading: see the file comment).
class Sink {
 public:
  virtual ~Sink() = default;

  /// where the loop calls this sink (SinkStage); kOutputs unless a sink says otherwise.
  virtual SinkStage stage() const { return SinkStage::kOutputs; }

  /// the loop starts. @throws anything: the loop then ends with that error before any step.
  virtual void OnStart(const LoopStart& start) {}

  /// what this sink needs of the snapshot at `step` (time `time_sec`); kNone = nothing. called
  /// once per step, in step order, before that step's snapshot is taken. the loop takes one
  /// snapshot per step with the richest content any sink asked for.
  virtual SnapshotContent Wants(int64_t step, double time_sec) = 0;

  /// a snapshot the loop took, in step order. every sink gets every snapshot, including those
  /// other sinks asked for (check snapshot->step; fields beyond the content asked for by some
  /// sink at that step may be empty).
  /// @throws anything: the loop records it as an error and ends.
  virtual void OnSnapshot(const std::shared_ptr<const WorldSnapshot>& snapshot) = 0;

  /// the loop ended (after the last OnSnapshot): finish the sink's work (drain its threads,
  /// close its files). called for every sink, also after an error, in stage order.
  /// @throws anything: recorded as an error of the run (first one wins).
  virtual void OnFinish(const LoopFinish& finish) {}
};

}  // namespace penumbra
