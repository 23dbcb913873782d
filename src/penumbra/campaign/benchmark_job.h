#pragma once
// one benchmark job: a recorded route (world) replayed under one condition with one seed
// (trial), exported as a dataset, every method run on it and evaluated. the job's results
// are one row per method (BenchmarkRow), written to OUT/jobs/<id>/result.json; a job with
// that file is finished (a re-run skips it).
//
// folders under the benchmark's output folder OUT:
//   recordings/<world>.plog          the route, recorded once (RecordingPath)
//   jobs/<id>/override.yaml          the replay's world override (camera, seed)
//   jobs/<id>/groundtruth.txt        the camera's ground truth (TUM, optical frame)
//   jobs/<id>/camera_info.json       the camera's calibration
//   jobs/<id>/replay/, dataset/      replayed run and exported dataset (removed unless
//                                    keep_datasets)
//   jobs/<id>/<method>/              the method's work folder: stdout.log, stderr.log, its
//                                    trajectory, estimate.txt (the trajectory as TUM seconds)
//   jobs/<id>/result.json            the rows

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "penumbra/campaign/benchmark_spec.h"
#include "penumbra/core/error.h"

namespace penumbra {

/// one (world, condition, trial); for a nav spec one (world, episode, condition, method,
/// trial) (campaign/nav_job.h).
struct BenchmarkJob {
  int index = 0;  ///< 0-based, world-major, then condition, then trial
  size_t world = 0, condition = 0, trial = 0;
  size_t episode = 0, method = 0;  ///< nav jobs only
  uint64_t seed = 0;
  std::string id;  ///< "<world>__<condition>__t<trial>" (trial 1-based)
};

/// one CSV row: (world, condition, method, trial). metrics are NaN unless status is "ok".
struct BenchmarkRow {
  std::string world, condition, method;
  int trial = 0;  ///< 1-based
  uint64_t seed = 0;
  /// ok | failed (non-zero exit or signal) | timeout | no_output (no trajectory file) |
  /// bad_output (not a trajectory) | lost (fewer than 2 poses match the ground truth)
  std::string status;
  std::string detail;  ///< how the method ended / why it failed
  int64_t frames = 0;  ///< frames in the dataset
  int64_t poses = 0;   ///< poses in the method's trajectory
  double ate_rmse_m = NAN, ate_mean_m = NAN, ate_max_m = NAN;
  double rpe_trans_rmse_m = NAN, rpe_rot_rmse_deg = NAN;
  double coverage = NAN, scaled_ate_m = NAN, tracked_fraction = NAN;
  /// beside the paper's coverage: the ground-truth path the tracked intervals cover / the whole
  /// ground-truth path, and ATE RMSE / that coverage (eval/trajectory_evaluation.h)
  double tracked_path_coverage = NAN, tracked_scaled_ate_m = NAN;
  /// the poses the ATE rests on: associated poses / the frames of the ground truth's span
  /// (eval/trajectory_evaluation.h pose_fraction), in [0, 1]
  double pose_fraction = NAN;
  double scale = NAN;  ///< the alignment's scale (1 for se3)
  /// wall times, s: replay (rendering) and export are per job (the same in each of its rows)
  double replay_sec = 0, export_sec = 0, method_sec = 0, eval_sec = 0;
};

/// thrown by a job that a stop request (SIGINT / SIGTERM) interrupted: its folder holds no
/// result.json and may hold partial outputs (RunBenchmarkWorker removes it).
class JobInterrupted : public Error {
 public:
  explicit JobInterrupted(const std::string& what) : Error(what) {}
};

/// what a job needs besides the spec.
struct BenchmarkJobContext {
  std::string out_dir;          ///< the benchmark's output folder
  std::string penumbra_binary;  ///< {penumbra}
  const std::atomic<int>* stop_request = nullptr;
  /// the render backend of the job's replay or run ("cpu", "cuda", "auto"; "" = the world's).
  std::string backend;
};

/// the jobs of a spec, in index order (a nav spec's: PlanNavJobs).
std::vector<BenchmarkJob> PlanBenchmarkJobs(const BenchmarkSpec& spec);

/// OUT/recordings/<world>.plog
std::string RecordingPath(const std::string& out_dir, const BenchmarkWorld& world);
/// OUT/jobs/<id>
std::string JobFolder(const std::string& out_dir, const BenchmarkJob& job);
/// OUT/jobs/<id>/result.json
std::string JobResultPath(const std::string& out_dir, const BenchmarkJob& job);

/// runs a job (its world's recording must exist) and writes its result.json.
/// @throws JobInterrupted when context.stop_request is set while it runs; ConfigError / Error
///         when the harness itself fails (replay, export, a write); a method's failure
///         (including a program that cannot be started) is a row, not an exception.
std::vector<BenchmarkRow> RunBenchmarkJob(const BenchmarkSpec& spec, const BenchmarkJob& job,
                                          const BenchmarkJobContext& context);

/// reads a job's result.json. @throws ConfigError naming the file if it is malformed.
std::vector<BenchmarkRow> ReadJobResult(const std::string& path);

}  // namespace penumbra
