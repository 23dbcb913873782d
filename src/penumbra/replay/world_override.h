#pragma once
// `penumbra replay --world OVERRIDE.yaml`: a world-file fragment whose top-level keys replace
// those of the recorded world, for what a replay may change: what is seen, never what moves.
//
//   replaced whole        cameras, mjcf_cameras, lights, sky, materials, render, effects,
//   (visual)              semantic_classes, output, adversity, agents, seed, and the top-level
//                         `sensors` list (the sensors listed under a robot stay: `robots` cannot
//                         change)
//   replaced whole        metrics: what is measured along the logged motion (a replay records
//   (measured)            the kinematic quantities only; metrics/metrics_sink.h)
//   refused (physics)     robots, models, physics: they change the model or its dynamics, which
//                         the log records; duration_sec: a replay's span is the log's (use
//                         --from / --to); any other key of the world file (e.g. record) is
//                         refused as not replaceable.
//
// a replaced key replaces the recorded key entirely (a `cameras` list replaces the recorded
// list: repeat a recorded camera to keep it); keys the override does not name stay as recorded.
// agents named as in the log follow the log whatever their new path (only their look changes);
// new agents move on their own and, like an adversity preset's NPCs added by a replay, keep
// clear of the logged robot (crowd agents); a kinematic replay refuses new agents that may touch
// it (replay/kinematic/replay_runner.h). `seed` changes noise, effects and a preset's NPC paths.
//
// the fragment is read as a world file at its own path: its relative paths resolve against its
// folder and its errors name its lines; names it uses (camera attach bodies, material names)
// are checked against the recorded models.

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "penumbra/core/error.h"
#include "penumbra/world/world_config.h"

namespace penumbra {

/// the top-level world-file keys an override may replace, in the order of the file header.
const std::vector<std::string_view>& ReplaceableWorldKeys();

/// what an override replaced.
struct WorldOverride {
  std::string file;               ///< the override file
  std::vector<std::string> keys;  ///< its top-level keys, in file order
  /// the line of every key path of the override file (for errors found later).
  std::shared_ptr<const LineTable> lines;
};

/// `recorded` with the top-level keys of the override file at `path` replaced (see the file
/// header); `applied` (may be null) receives the file, its keys and its lines.
/// @throws ConfigError(path, line, key, ...) for a missing or unreadable file, a document that
///         is not a block mapping, a key that changes physics (naming the key and why) or is
///         not replaceable, and every error of the world-file reader for the fragment's values
///         (unknown keys, types, ranges, unknown models in attach names, duplicate sensor names).
WorldConfig ApplyWorldOverride(const WorldConfig& recorded, const std::string& path,
                               WorldOverride* applied = nullptr);

/// `e` (raised while a replay sets up) with the file and line filled in: the override's when
/// `e`'s key lies under a key the override replaced (e.g. "cameras[1].attach"), else as
/// LocateInWorld(world, e) does for the recorded world.
ConfigError LocateReplayError(const WorldConfig& world, const WorldOverride& applied,
                              const ConfigError& e);

}  // namespace penumbra
