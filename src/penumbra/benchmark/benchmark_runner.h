#pragma once
// `penumbra benchmark SPEC.yaml --out DIR` (docs/benchmarks.md): the spec is loaded and
// checked; every world's route is recorded once (OUT/recordings/<world>.plog); the jobs
// (world x condition x trial, benchmark/benchmark_job.h) run as worker processes of this
// binary (`penumbra benchmark SPEC --out DIR --job K`), N at a time locally, or as one Slurm
// job array (one task per job, `sbatch`, then `squeue` until none is left); the results are
// collected into results.csv, the summary, the plots and report.md
// (benchmark/benchmark_report.h). jobs that finished earlier (their result.json exists) are
// skipped, so running the same command again resumes an interrupted benchmark, and
// re-submitting to Slurm submits only the unfinished jobs.

#include <atomic>
#include <functional>
#include <string>

#include "penumbra/benchmark/benchmark_spec.h"

namespace penumbra {

/// records `world`'s route into the run log `plog_path` (penumbra run --record, no cameras).
using RecordRouteFn =
    std::function<void(const BenchmarkWorld& world, const std::string& plog_path)>;

/// what `penumbra benchmark` is asked for.
struct BenchmarkOptions {
  std::string spec_path;
  std::string out_dir;
  std::string penumbra_binary;  ///< this executable, for the workers and {penumbra}
  int workers = 0;              ///< 0 = the spec's `workers`
  bool slurm = false;           ///< submit a Slurm job array instead of local workers
  bool force = false;           ///< remove an earlier benchmark's outputs from out_dir first
  bool progress = true;
  RecordRouteFn record;
  const std::atomic<int>* stop_request = nullptr;
};

/// runs the whole benchmark; returns the exit code: 0 when every job finished (methods may
/// have failed: those are rows), 1 when a job's harness failed (the message names its log).
/// @throws ConfigError for a bad spec, an output folder holding another spec's results
///         (without force) or a missing `sbatch`; Error for a write failure.
int RunBenchmark(const BenchmarkOptions& options);

/// the worker side: runs job `index` of the spec into out_dir (the recording must exist).
/// @throws ConfigError for an index out of range; what RunBenchmarkJob throws.
void RunBenchmarkWorker(const std::string& spec_path, const std::string& out_dir, int index,
                        const std::string& penumbra_binary, const std::atomic<int>* stop_request);

/// the Slurm batch script for the unfinished jobs `indices` (also written by RunBenchmark
/// as OUT/slurm/array.sbatch).
std::string SlurmBatchScript(const BenchmarkSpec& spec, const std::string& out_dir,
                             const std::string& penumbra_binary, const std::vector<int>& indices);

}  // namespace penumbra
