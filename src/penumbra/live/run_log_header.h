#pragma once
// the run log header (runlog/run_log_format.h) of a Session: versions, the world or model
// text, the composed MJCF, content hashes of every file read, seed, command line, timestep
// and the state layout with names.

#include <string>

#include "penumbra/runlog/run_log_format.h"
#include "penumbra/session/session.h"

namespace penumbra {

/// the state layout of `sim`'s model (RunLogLayout: SimState sizes, the joints with their qpos
/// and qvel addresses and widths, actuators, mocap bodies, bodies and controllers by name): the
/// header's layout, and what a replay maps a logged state onto (replay/state_map.h).
RunLogLayout RunLogLayoutOf(const Simulation& sim);

/// the header of a log of `session`'s run. the files hashed: the world file (role "world"),
/// every model file ("model"), the adversity preset file when the world names one by path
/// ("adversity"), and every mesh, skin, height field and texture file of the composed MJCF
/// (compose/mjcf_assets.h). a file that cannot be read gets sha256 "" (it was read when the
/// session was set up, so this only happens when it changed since).
/// @param penumbra_version  the writer's version (PENUMBRA_VERSION)
/// @param command_line      the command as typed, arguments joined by spaces
/// @throws Error when the world file or a model file cannot be read for its text.
RunLogHeader MakeRunLogHeader(const Session& session, const std::string& penumbra_version,
                              const std::string& command_line);

}  // namespace penumbra
