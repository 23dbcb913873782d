#pragma once
// SimLoop: advances a Source (pipeline/source.h) on its own thread and hands the snapshots to
// registered Sinks (pipeline/sink.h):
//
//   for each step of the source:
//     content = richest of every sink's Wants(step, time)
//     if content != kNone: snapshot = source.Snapshot(content); every sink's OnSnapshot(snapshot)
//     stop if time >= end time, a stop was requested or an error was recorded
//     source.Advance()
//   every sink's OnFinish
//
// errors: the first error of the run (the source, a sink method, or a sink's own thread through
// LoopStart::report_error) is kept (pipeline/first_error.h); the loop ends at the next step
// boundary, every sink still gets OnFinish, and Wait returns the error in LoopFinish::error.

#include <atomic>
#include <limits>
#include <memory>
#include <thread>
#include <vector>

#include "penumbra/pipeline/first_error.h"
#include "penumbra/pipeline/sink.h"
#include "penumbra/pipeline/source.h"

namespace penumbra {

/// settings of a SimLoop.
struct SimLoopOptions {
  /// the loop ends after the snapshot of the first step whose time is >= end_time_sec - 1e-9 s.
  double end_time_sec = std::numeric_limits<double>::infinity();
  /// a stop request (e.g. set by a SIGINT handler; null = none): when it reads non-zero the
  /// loop ends at the next step boundary (after that step's snapshot) with kStopRequested; so
  /// does a source whose Advance returns false while it reads non-zero.
  const std::atomic<int>* stop_request = nullptr;
};

/// runs one source into its sinks on a thread of its own.
class SimLoop {
 public:
  /// `source` and every sink must outlive the loop.
  explicit SimLoop(Source* source, SimLoopOptions options = {});
  /// waits for the loop thread if it runs.
  ~SimLoop();
  SimLoop(const SimLoop&) = delete;
  SimLoop& operator=(const SimLoop&) = delete;

  /// registers a sink; before Start. sinks are called in the order of their stage
  /// (Sink::stage(), pipeline/sink.h), and in registration order within a stage.
  /// @throws Error if the loop was started.
  void AddSink(Sink* sink);

  /// starts the loop thread. @throws Error if it was started before.
  void Start();
  /// waits for the loop thread to end; how it ended. @throws Error if it was not started.
  LoopFinish Wait();
  /// Start then Wait.
  LoopFinish Run() {
    Start();
    return Wait();
  }

  /// the sinks in the order the loop calls them (by stage, then registration).
  std::vector<Sink*> OrderedSinks() const;

  /// records an error (thread-safe; the first one wins) and ends the loop at the next step
  /// boundary; true if it was the first. also usable after the loop ended, for errors of
  /// the run's last steps (e.g. writing the manifest).
  bool ReportError(std::exception_ptr e);
  /// the first error recorded so far, or null.
  std::exception_ptr first_error() const { return errors_.get(); }

 private:
  void Loop();

  Source* source_;
  SimLoopOptions options_;
  std::vector<Sink*> sinks_;
  FirstError errors_;
  std::atomic<bool> failed_{false};
  std::thread thread_;
  bool started_ = false;
  LoopFinish finish_;
};

}  // namespace penumbra
