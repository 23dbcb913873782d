#pragma once
// `penumbra run`: the whole pipeline for one world file. world file -> composer ->
// physics on its own thread -> snapshots at camera times -> renderer -> outputs.

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "penumbra/world/world_config.h"

namespace penumbra {

/// options given on the command line that are not part of the world file.
struct RunOptions {
  std::string out_dir;                 ///< output folder; "" = world's output.dir
  std::optional<double> duration_sec;  ///< overrides the world's duration
  bool realtime = false;               ///< pace physics to wall-clock time (default: as fast as possible)
  bool progress = true;                ///< progress bar on a terminal / log lines otherwise
  std::vector<std::string> command_line;  ///< argv, recorded in run.json
  /// adversity preset spec (--adversity; world/adversity_preset.h), "" = the world's own
  std::string adversity;
};

/// what a run produced.
struct RunSummary {
  std::string out_dir;
  double sim_time_sec = 0;
  int64_t physics_steps = 0;
  std::map<std::string, int64_t> frames_per_camera;
  double wall_time_sec = 0;
  double peak_rss_mib = 0;
};

/// runs `world` and writes every output under the output folder (see README "Outputs").
/// physics runs on its own thread; rendering and writing happen on the caller's thread
/// and a writer pool. frames already written are kept if the run fails part-way.
/// @throws ConfigError for bad input (before anything runs), PhysicsError if the
///         simulation diverges (after flushing outputs and run.json).
RunSummary RunWorld(const WorldConfig& world, const RunOptions& options);

}  // namespace penumbra
