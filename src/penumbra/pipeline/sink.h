#pragma once
// a consumer of the snapshots a SimLoop (pipeline/sim_loop.h) takes from its source: cameras,
// sensors, the trajectory file, the run manifest; later recorders, bridges, viewers.
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

/// receives snapshots from a SimLoop (threading: see the file comment).
class Sink {
 public:
  virtual ~Sink() = default;

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
  /// close its files). called for every sink, also after an error, in registration order.
  /// @throws anything: recorded as an error of the run (first one wins).
  virtual void OnFinish(const LoopFinish& finish) {}
};

}  // namespace penumbra
