#pragma once
// DIR/run.json: what produced an output folder (world, seed, versions, command line)
// and how the run went (frames, timings, peak memory), for reproducing and
// comparing runs.

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace penumbra {

/// what a replay (`penumbra replay`, replay/kinematic/replay_runner.h) rendered, and how:
/// run.json's "replay" object.
struct ReplayManifest {
  std::string log;  ///< the run log replayed, as given on the command line
  /// "kinematic" (the log's states, no physics), "resimulate" (physics again, the world's
  /// controllers) or "resimulate ctrl" (physics again, the logged ctrl)
  std::string mode;
  int64_t first_step = 0, last_step = 0;  ///< the logged steps replayed
  /// the changes to the recorded conditions: the --world override file ("" = none) and the
  /// keys it replaced, --adversity ("" = as recorded), --tier ("" = as recorded), --cameras
  /// (empty = all), --outputs ("" = as recorded).
  std::string world_override;
  std::vector<std::string> override_keys;
  std::string adversity;
  std::string tier;
  std::vector<std::string> cameras;
  std::string outputs;
  /// warnings about the log or its assets (a damaged log, a model file changed since it was
  /// recorded), in the order they were found.
  std::vector<std::string> warnings;
  /// a resimulation's verdict (ResimulateReport::Describe: "bit-exact (N steps)", "diverged
  /// at step ..."); "" (and no key) for a kinematic replay.
  std::string verdict;
};

/// contents of run.json. the file lists the keys in this order (stable across runs);
/// maps are sorted by key.
struct RunManifest {
  std::string world_file;  ///< path of the world file or bare model
  uint64_t seed = 0;
  std::string penumbra_version;           ///< e.g. "0.1.0"
  std::string mujoco_version;             ///< e.g. "4.0.0" (mj_versionString)
  std::string embree_version;             ///< e.g. "3.13.5"
  std::vector<std::string> command_line;  ///< argv, one entry per argument
  double sim_duration_sec = 0;  ///< sim time reached: time of the last completed physics step
  /// true when the run was stopped early (SIGINT / SIGTERM); written always
  bool interrupted = false;
  std::map<std::string, int64_t> frames_per_camera;  ///< frames written per camera name
  std::map<std::string, double> timings_sec;         ///< wall-clock per stage, e.g. "render": 12.5
  double peak_resident_memory_mib = 0;  ///< usually PeakResidentMemoryMiB() at the end of the run
  /// adverse conditions, written only when any is set: the adversity preset
  /// ("name (file)"), the effects ("name: type") and the NPC agents ("name: kind") in order.
  std::string adversity;
  std::vector<std::string> effects;
  std::vector<std::string> agents;
  /// the run log (--record, world `record:`), written only when record_file is not empty:
  /// "record": {"file", "bytes", "steps", "first_step", "last_step", "events",
  /// "sensor_records"} after "agents".
  std::string record_file;
  uint64_t record_bytes = 0;  ///< size of the log file
  int64_t record_steps = 0;   ///< step records in the log
  int64_t record_first_step = -1, record_last_step = -1;
  int64_t record_events = 0;
  int64_t record_sensor_records = 0;
  /// the fall verdicts of the floating-base robots (metrics/fall_detector.h,
  /// FallSink::SummaryJson): a JSON object as text, written as the key "falls" after "record"
  /// (before "replay" and "metrics") only when not empty.
  std::string falls_json;
  /// the world file's `metrics:` summaries (metrics/metrics_sink.h, MetricsSink::SummaryJson):
  /// a JSON object as text, written as the key "metrics" (last) only when not empty.
  std::string metrics_json;
  /// the run's first error (e.g. divergence, a file that could not be written); the key
  /// "error" is written only when it is not empty, after "peak_resident_memory_mib".
  std::string error;
  /// set for a replay: the key "replay" is written last, only then.
  std::optional<ReplayManifest> replay;
};

/// the manifest as pretty-printed JSON text (2-space indent, trailing newline).
std::string RunManifestJson(const RunManifest& manifest);

/// writes RunManifestJson(manifest) to DIR/run.json, creating DIR if needed; whole under a
/// temporary name, then renamed into place (core/output_file.h).
/// @throws Error naming the path if it cannot be written.
void WriteRunManifest(const std::string& output_dir, const RunManifest& manifest);

/// peak resident set size of this process in MiB (VmHWM of /proc/self/status, Linux);
/// 0 when it cannot be read.
double PeakResidentMemoryMiB();

}  // namespace penumbra
