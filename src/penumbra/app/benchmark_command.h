#pragma once
// `penumbra benchmark SPEC.yaml --out DIR [--workers N] [--slurm] [--force] [--quiet]` runs a
// perception benchmark (campaign/benchmark_runner.h, docs/benchmarks.md); `--job K` is the
// worker side (one job, as local workers and Slurm array tasks run it).
// `penumbra slam METHOD DATASET OUT --intrinsics fx,fy,cx,cy | --camera-info FILE` runs a
// bundled RGB-D odometry method (slam/rgbd_odometry.h) over a TUM RGB-D folder and writes
// its trajectory (TUM format).

#include <memory>

#include "penumbra/app/command.h"

namespace penumbra {

/// the `benchmark` verb (app/command.h), with SIGINT / SIGTERM handlers (app/stop_signals.h).
std::unique_ptr<Command> MakeBenchmarkCommand();
/// the `slam` verb (app/command.h).
std::unique_ptr<Command> MakeSlamCommand();

}  // namespace penumbra
