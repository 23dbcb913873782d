#pragma once
// DIR/run.json: what produced an output folder (world, seed, versions, command line)
// and how the run went (frames, timings, peak memory), for reproducing and
// comparing runs.

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace penumbra {

/// contents of run.json. the file lists the keys in this order (stable across runs);
/// maps are sorted by key.
struct RunManifest {
  std::string world_file;  ///< path of the world file or bare model
  uint64_t seed = 0;
  std::string penumbra_version;                      ///< e.g. "0.1.0"
  std::string mujoco_version;                        ///< e.g. "2.2.2" (mj_versionString)
  std::string embree_version;                        ///< e.g. "3.13.5"
  std::vector<std::string> command_line;             ///< argv, one entry per argument
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
  /// the world file's `metrics:` summaries (metrics/metrics_sink.h, MetricsSink::SummaryJson):
  /// a JSON object as text, written as the key "metrics" (last) only when not empty.
  std::string metrics_json;
  /// the run's first error (e.g. divergence, a file that could not be written); the key
  /// "error" is written only when it is not empty, after "peak_resident_memory_mib".
  std::string error;
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
