#pragma once
// `penumbra bench record`: the cost of recording a run log (runlog/, docs/run-log.md) on a
// real world: physics steps/s of the pipeline (PhysicsSource -> SimLoop) with the recorder
// sink and without it, in interleaved A/B rounds, and the size of a log of 60 s. a benchmark,
// never a pass/fail test: it prints numbers and the targets (ratio >= 0.9, 60 s < 50 MB).

#include <memory>
#include <string>

#include "penumbra/runlog/run_log_writer.h"

namespace penumbra {

/// options of `penumbra bench record`.
struct BenchRecordOptions {
  std::string world_file;     ///< world to step (default: the bundled default world)
  double round_seconds = 10;  ///< simulated seconds per timed round
  int rounds = 3;             ///< A/B pairs (recording off, then on), >= 1
  double size_seconds = 60;   ///< simulated seconds of the log whose size is reported
  std::string log_dir;        ///< where the logs go ("" = the temporary folder); removed after
  int zstd_level = RunLogWriterOptions{}.zstd_level;  ///< the writer's compression level
};

/// the verb as registered on `penumbra bench`.
/// runs the benchmark with `options`, prints its table to stdout. returns 0.
int BenchRecord(const BenchRecordOptions& options);

}  // namespace penumbra
