#pragma once
// the run's trajectory file as a pipeline sink (pipeline/sink.h):
//
//   <out>/trajectory.csv   step,time_sec,qpos0,...,qpos<nq-1>: one row per physics step
//                          taken (steps 1, 2, ...; not the initial state), numbers printed
//                          with 17 significant digits ({:.17g}, reads back to the same double)
//
// rows are formatted and written on the sink's own thread (pipeline/sink_worker.h), never on
// the loop (physics) thread; the file only ever holds whole rows (core/output_file.h).

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>

#include "penumbra/core/output_file.h"
#include "penumbra/pipeline/sink.h"
#include "penumbra/pipeline/sink_worker.h"

namespace penumbra {

/// the header line of trajectory.csv for `nq` joint coordinates (with '\n').
std::string TrajectoryHeader(size_t nq);
/// one trajectory.csv row for `snapshot` (step, time_sec, qpos; with '\n').
std::string TrajectoryRow(const WorldSnapshot& snapshot);

/// writes trajectory.csv from kState snapshots of every step after the first.
class TrajectorySink : public Sink {
 public:
  /// creates `path` now with the header for `nq` coordinates.
  /// @throws Error naming the path if it cannot be created.
  TrajectorySink(const std::filesystem::path& path, size_t nq);

  void OnStart(const LoopStart& start) override;
  /// kState at every step >= 1.
  SnapshotContent Wants(int64_t step, double time_sec) override;
  /// queues the row of every snapshot of a step >= 1 not written yet.
  void OnSnapshot(const std::shared_ptr<const WorldSnapshot>& snapshot) override;
  /// writes the queued rows and closes the file. @throws Error if a write failed.
  void OnFinish(const LoopFinish& finish) override;

 private:
  LineFile file_;
  SinkWorker worker_;
  int64_t last_step_ = 0;
};

}  // namespace penumbra
