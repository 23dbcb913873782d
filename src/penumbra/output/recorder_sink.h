#pragma once
// the run log recorder as a pipeline sink (pipeline/sink.h): asks for the state
// (SnapshotContent::kState) at every step, the initial state (step 0) included, and appends it
// to a RunLogWriter (runlog/run_log_writer.h), whose own thread compresses and writes. the
// loop (physics) thread only copies the state into the writer's open chunk.

#include <cstdint>
#include <memory>
#include <string>

#include "penumbra/pipeline/sink.h"
#include "penumbra/runlog/run_log_writer.h"

namespace penumbra {

/// records every step of a run into a run log.
class RecorderSink : public Sink {
 public:
  /// SinkStage::kRecording: after the outputs: the step's sensor records reach the log first.
  SinkStage stage() const override { return SinkStage::kRecording; }
  /// opens the log: creates `path` and writes its header now.
  /// @throws RunLogError naming the path when it cannot be created or written.
  RecorderSink(const std::string& path, const RunLogHeader& header,
               const RunLogWriterOptions& options = {});
  /// as above, into a file the caller opened (output/output_lock.h OpenRunLogFile,
  /// core/output_path_policy.h OpenNewFileInside); the writer owns `fd` from here on. `name`
  /// stands for the file in errors and stats.
  /// @throws RunLogError naming `name` when the header cannot be written.
  RecorderSink(UniqueFd fd, const std::string& name, const RunLogHeader& header,
               const RunLogWriterOptions& options = {});
  ~RecorderSink() override;

  /// kState at every step from the loop's first (step 0 of a fresh run).
  SnapshotContent Wants(int64_t step, double time_sec) override;
  /// appends the snapshot's state (once per step).
  /// @throws RunLogError from RunLogWriter::Append (a writer-thread error, a size mismatch).
  void OnSnapshot(const std::shared_ptr<const WorldSnapshot>& snapshot) override;
  /// closes the log (after an error or a stop request too, so that the log is complete up to
  /// the last step taken). @throws RunLogError from RunLogWriter::Close.
  void OnFinish(const LoopFinish& finish) override;

  /// the writer, for events and sensor records from other threads (thread-safe calls only);
  /// valid for the sink's lifetime.
  RunLogWriter& writer() { return *writer_; }
  /// the writer's counters (after OnFinish: the final ones).
  RunLogWriterStats stats() const { return writer_->stats(); }

 private:
  std::unique_ptr<RunLogWriter> writer_;
  int64_t last_step_ = -1;
};

}  // namespace penumbra
