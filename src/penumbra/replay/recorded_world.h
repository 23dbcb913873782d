#pragma once
// the world a run log was recorded with, rebuilt from its header (runlog/run_log_format.h):
// the world file's TEXT as recorded (not the file on disk today), parsed as if it still were
// at its recorded path so that its relative paths (models, textures, presets) resolve as they
// did; a bare-model run (`penumbra run model.xml`) gets WorldForBareModel of the recorded
// model file. the run's command-line changes to its world come back too: the seed from the
// header, and --adversity, --tier, --spp and --outputs from its recorded command line.

#include <optional>
#include <string>
#include <vector>

#include "penumbra/runlog/run_log_format.h"
#include "penumbra/world/world_config.h"

namespace penumbra {

class LiveEffects;

/// the flags of a recorded `penumbra run` command line that change what its outputs show
/// (the seed is the header's own field).
struct RecordedRunFlags {
  std::string adversity;                 ///< --adversity spec, "" = the world's own
  std::optional<std::string> tier;       ///< --tier: "realtime" or "pathtraced"
  std::optional<int> samples_per_pixel;  ///< --spp
  std::optional<std::string> outputs;    ///< --outputs list, e.g. "rgb,depth"
  /// a live run: --zmq, --ros or --viewer given, or the `view` verb (its model has the
  /// reserved NPC bodies: SessionOptions::reserve_live_npcs)
  bool live = false;
};

/// the flags of `command_line` (RunLogHeader::command_line: the arguments joined by spaces),
/// written "--flag value" or "--flag=value"; a flag given twice keeps the last value (as the
/// command-line parser did). unrelated arguments are skipped.
RecordedRunFlags ParseRecordedRunFlags(const std::string& command_line);

/// the recorded world (see the file header) with the header's seed and the recorded
/// --tier, --spp and --outputs applied (--adversity is RecordedRunFlags::adversity, given to
/// the Session), and its `record:` cleared (a replay writes no run log). world.file is the
/// recorded world file path.
/// @throws ConfigError naming the recorded world file and line (as `run` would) when the
///         recorded text no longer loads, e.g. a model file it names is gone.
WorldConfig RecordedWorld(const RunLogHeader& header);

/// schedules the change a "live" event of the log carries (its JSON payload) at the event's
/// step: LiveEffects::ScheduleRecorded (live/live_effects.h).
/// @throws ConfigError naming `log_path` and the event's step when the payload is not JSON.
void ScheduleRecordedLiveChange(const EventRecord& e, const std::string& log_path,
                                LiveEffects* live);

/// one line per recorded asset whose content differs today from its hash in the log (or that
/// cannot be read): "model /abs/quadruped.xml changed since the run was recorded (sha256
/// 1a2b... in the log, 3c4d... now)". the world file is skipped (its recorded text is used).
std::vector<std::string> ChangedAssets(const RunLogHeader& header);

}  // namespace penumbra
