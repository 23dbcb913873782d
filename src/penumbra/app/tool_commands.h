#pragma once
// the `penumbra` tool verbs that write one file from a world (app/command.h):
//   heightfield     a world's static geometry sampled into a MuJoCo hfield (app/heightfield_tool.h)
//   contact-sheet   one instant under adversity presets side by side (app/contact_sheet.h)
//   npc-map         the NPCs' walkable map as a PNG (app/npc_map_command.h)
//   make-vdb        a procedural smoke cloud as an OpenVDB file (app/vdb_tool.h)

#include <memory>

#include "penumbra/app/command.h"

namespace penumbra {

std::unique_ptr<Command> MakeHeightfieldCommand();
std::unique_ptr<Command> MakeContactSheetCommand();
std::unique_ptr<Command> MakeNpcMapCommand();
std::unique_ptr<Command> MakeMakeVdbCommand();

}  // namespace penumbra
