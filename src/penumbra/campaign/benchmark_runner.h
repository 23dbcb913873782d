#pragma once
// `penumbra benchmark SPEC.yaml --out DIR` (docs/benchmarks.md): the spec is loaded and
// checked; every world's route is recorded once (OUT/recordings/<world>.plog); the jobs
// (world x condition x trial, campaign/benchmark_job.h) run as worker processes of this
// binary (`penumbra benchmark SPEC --out DIR --job K`), N at a time locally, or as one Slurm
// job array (one task per job, `sbatch`, then `squeue` until none is left); the results are
// collected into results.csv, the summary, the plots and report.md
// (campaign/benchmark_report.h). jobs that finished earlier (their result.json exists) are
// skipped, so running the same command again resumes an interrupted benchmark, and
// re-submitting to Slurm submits only the unfinished jobs.

#include <atomic>
#include <functional>
#include <string>

#include "penumbra/campaign/benchmark_spec.h"

namespace penumbra {

/// records `world`'s route into the run log `plog_path` (penumbra run --record, no cameras);
/// returns early (the log possibly partial: RunBenchmark removes it) once *stop_request is set.
using RecordRouteFn = std::function<void(const BenchmarkWorld& world, const std::string& plog_path,
                                         const std::atomic<int>* stop_request)>;

/// what `penumbra benchmark` is asked for.
struct BenchmarkOptions {
  std::string spec_path;
  std::string out_dir;
  std::string penumbra_binary;  ///< this executable, for the workers and {penumbra}
  int workers = 0;              ///< 0 = the spec's `workers`
  bool slurm = false;           ///< submit a Slurm job array instead of local workers
  bool force = false;           ///< remove an earlier benchmark's outputs from out_dir first
  bool progress = true;
  /// the render backend of every job ("cpu", "cuda", "auto"; `penumbra benchmark --backend`),
  /// passed to each worker as --backend; "" = the worlds' render.backend.
  std::string backend;
  RecordRouteFn record;
  const std::atomic<int>* stop_request = nullptr;
};

/// runs the whole benchmark; returns the exit code: 0 when every job finished (methods may
/// have failed: those are rows), 1 when a job's harness failed (the message names its log),
/// 128 + the signal (130 SIGINT, 143 SIGTERM) when *stop_request was set: the route being
/// recorded is removed, local workers get SIGTERM once (each stops its method's process
/// group and removes its unfinished job folder; the workers run in their own process groups,
/// so a terminal's Ctrl-C reaches only this process), a Slurm array is cancelled, and the
/// report is written over the jobs that finished (each result.json is written atomically,
/// last), so the same command resumes.
/// @throws ConfigError for a bad spec, an output folder holding another spec's results
///         (without force), a missing `sbatch`, or with `slurm` an output folder, spec path or
///         binary path that a batch script cannot carry (CheckSlurmPaths); Error for a write
///         failure.
int RunBenchmark(const BenchmarkOptions& options);

/// the worker side: runs job `index` of the spec into out_dir (the recording must exist).
/// returns 0, or 128 + the signal when *stop_request interrupted the job (its folder is then
/// removed: no partial job is left).
/// @throws ConfigError for an index out of range; what RunBenchmarkJob throws.
/// `backend` ("" = the worlds' render.backend) renders the job's replay or run.
int RunBenchmarkWorker(const std::string& spec_path, const std::string& out_dir, int index,
                       const std::string& penumbra_binary, const std::atomic<int>* stop_request,
                       const std::string& backend = "");

/// checks what a Slurm batch script interpolates: `out_dir` (absolute; it goes into the
/// `#SBATCH --output=` line and the command line), the spec file and the binary (the command
/// line). refused: control characters (newline, carriage return, NUL, tab, any byte below
/// 0x20 and 0x7f) anywhere, and in `out_dir` also whitespace, quotes, '\', '#' and '%' (an
/// #SBATCH line ends at a blank and a '#', and Slurm reads '%' and '\' in --output).
/// @throws ConfigError("", 0, "--out" | "spec" | "binary", problem) naming the character and
///         its offset.
void CheckSlurmPaths(const std::string& out_dir, const std::string& spec_file,
                     const std::string& penumbra_binary);

/// the Slurm batch script for the unfinished jobs `indices` (also written by RunBenchmark
/// as OUT/slurm/array.sbatch). every interpolated path is checked (CheckSlurmPaths) and the
/// command line's words are quoted with ShellQuote (campaign/shell_quote.h). `backend` (""
/// = none) is passed to each task as --backend.
/// @throws ConfigError as CheckSlurmPaths, or for an extra `#SBATCH` line holding a control
///         character.
std::string SlurmBatchScript(const BenchmarkSpec& spec, const std::string& out_dir,
                             const std::string& penumbra_binary, const std::vector<int>& indices,
                             const std::string& backend = "");

}  // namespace penumbra
