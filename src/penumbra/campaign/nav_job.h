#pragma once
// one navigation benchmark job: (world, episode, condition, method, trial). the harness
// starts the simulator, `penumbra run WORLD --zmq tcp://127.0.0.1:<free port> --lockstep
// --adversity C --seed S --duration <episode timeout> --override override.yaml`, and the
// method's command (an external process given the endpoint, its argument vector expanded
// from the template without a shell: campaign/command_template.h) side by side. the episode ends
// when the method exits (the harness then stops the run with SIGTERM: outputs and run.json
// are written), when the run reaches the episode's sim timeout (the method gets 3 s of wall
// time to exit, then its process group is killed), or at the method's wall-clock timeout
// (both are stopped). the override adds two metric series to the run (metrics/metrics_sink.h):
// the robot base's pose (nav_base.csv) and the robot's contacts with anything but its own
// parts and its feet/wheels on the floor, undebounced (nav_contacts_episodes.csv). the row's
// metrics come from those files alone (campaign/nav_metrics.h), never from the method. the
// robot is one side of every contact pair (all its bodies are named after it), so a collision
// is (robot, environment body): a trunk and two legs against one wall within the debounce
// window are one collision, the wall and then a table two.
//
// files under OUT/jobs/<id>/:
//   override.yaml     the run's world override (metrics)
//   run/              the run's outputs (run.json, metrics/, trajectory.csv, camera images)
//   run.log           the run's stdout and stderr
//   <method>/         the method's work folder ({out_dir}): command.sh, stdout.log,
//                     stderr.log, whatever it writes (the bundled navigator: episode.json)
//   result.json       the row and the base path (written last: the job is finished)

#include <atomic>
#include <string>
#include <utility>
#include <vector>

#include "penumbra/campaign/benchmark_job.h"
#include "penumbra/campaign/benchmark_spec.h"

namespace penumbra {

/// one results.csv row of a nav benchmark (docs/benchmarks.md "Navigation" lists the columns).
struct NavRow {
  std::string world, episode, condition, method;
  int trial = 0;  ///< 1-based
  uint64_t seed = 0;
  /// ok | failed (the method crashed: a signal, or a non-zero exit before the goal, a fall or
  /// the sim timeout) | timeout (wall-clock limit, killed) | run_failed (the simulator failed)
  std::string status;
  /// why the episode ended: method_exit | sim_timeout | fall | wall_timeout | run_failed
  std::string end;
  std::string detail;  ///< the method's and the run's exit, and why a row is not ok
  double goal_x = 0, goal_y = 0, radius_m = 0, timeout_sec = 0;
  bool success = false;
  int collisions = 0;      ///< collisions the robot caused (SC counts these)
  int agent_contacts = 0;  ///< contacts an agent made (campaign/nav_metrics.h AgentMadeContact)
  double time_to_goal_sec = NAN;  ///< NaN unless success
  double final_goal_distance_m = NAN, episode_time_sec = NAN, path_length_m = NAN;
  double sc = 0;  ///< S / (1 + c)
  bool fell = false;
  double method_sec = 0, run_sec = 0, eval_sec = 0;  ///< wall times, s
  std::vector<std::pair<double, double>> path_xy;    ///< base xy at 10 Hz (plots), m
};

/// the nav jobs of a spec (kind: nav), in index order: world, episode, condition, method,
/// trial; id "<world>__<episode>__<condition>__<method>__t<trial>".
std::vector<BenchmarkJob> PlanNavJobs(const BenchmarkSpec& spec);

/// runs one nav job and writes its result.json (see the file comment).
/// @throws JobInterrupted when context.stop_request is set during the episode (the method and
///         the run are stopped first); Error when the harness itself fails (a write, no free
///         port); a failing method (one that cannot be started included) or simulator is a
///         row, not an exception.
NavRow RunNavJob(const BenchmarkSpec& spec, const BenchmarkJob& job,
                 const BenchmarkJobContext& context);

/// whether a nav episode's run delivered its outputs, from how its process ended (exit_code,
/// signal as ChildProcess reports them) and its output folder `run_dir`: it exited 0, or it was
/// stopped by the harness's SIGTERM (or a SIGINT) and either its handler ended it (exit 143 or
/// 130: it wrote its outputs) or the signal itself ended it after it had written run.json (the
/// run's last file, output/run_manifest.h: a run that had reached its duration and was
/// closing down when the SIGTERM came). anything else (another exit code or signal, no
/// run.json after a bare signal) is a failed run.
bool NavRunDelivered(int exit_code, int signal, const std::string& run_dir);

/// reads a nav job's result.json. @throws ConfigError naming the file if it is malformed.
NavRow ReadNavJobResult(const std::string& path);

/// the folder holding the bundled navigator (the source tree's python/), {pythonpath}.
std::string NavPythonPath();

}  // namespace penumbra
