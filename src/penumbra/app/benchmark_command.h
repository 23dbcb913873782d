#pragma once
// `penumbra benchmark SPEC.yaml --out DIR [--workers N] [--slurm] [--force] [--quiet]` runs a
// perception benchmark (campaign/benchmark_runner.h, docs/benchmarks.md); `--job K` is the
// worker side (one job, as local workers and Slurm array tasks run it).
// `penumbra slam METHOD DATASET OUT --intrinsics fx,fy,cx,cy | --camera-info FILE` runs a
// bundled RGB-D odometry method (slam/rgbd_odometry.h) over a TUM RGB-D folder and writes
// its trajectory (TUM format).

#include <atomic>
#include <memory>
#include <string>

namespace CLI {
class App;
}

namespace penumbra {

/// the `benchmark` and `slam` verbs: their options registered on a CLI11 app, and their runs.
class BenchmarkCommands {
 public:
  /// registers both verbs on `app`.
  explicit BenchmarkCommands(CLI::App& app);
  ~BenchmarkCommands();
  BenchmarkCommands(BenchmarkCommands&&) noexcept;
  BenchmarkCommands& operator=(BenchmarkCommands&&) noexcept;

  /// true when the parsed command line chose `benchmark` or `slam`.
  bool Selected() const;

  /// runs the chosen verb; returns the exit code (benchmark: RunBenchmark's, with --job
  /// RunBenchmarkWorker's; both 128 + the signal when *stop_request interrupted them; slam: 0,
  /// or 3 when no frame was tracked after the first).
  /// @throws ConfigError for bad input (exit code 2 in RunCli); Error for failures.
  int Run(const std::atomic<int>* stop_request) const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace penumbra
