#pragma once
// `penumbra run WORLD [options]`: a world file or a bare MJCF/URDF model simulated and its
// outputs written (run/runner.h RunWorld; README "Outputs"), with the bridges' and the
// viewer's flags (app/bridge_flags.h, app/viewer_commands.h).

#include <memory>

#include "penumbra/app/command.h"

namespace penumbra {

/// the `run` verb (app/command.h).
std::unique_ptr<Command> MakeRunCommand();

}  // namespace penumbra
