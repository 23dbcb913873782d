#pragma once
// `penumbra npc-map WORLD --out map.png`: the walkable map of a world's NPCs (session/npc_map.h)
// as a PNG: the regions of people and vehicles, the world's areas and lanes, the robots' starts
// and the crowd agents' starts (docs/npcs.md).

#include <string>

namespace penumbra {

/// options of `penumbra npc-map`.
struct NpcMapOptions {
  std::string world_file;
  std::string out = "npc_map.png";
  std::string adversity;    ///< a preset spec (--adversity), "" = the world's own
  int pixels_per_cell = 4;  ///< [1, 16] pixels per 0.1 m cell
};

/// loads the world (no renderer, no controllers), builds its walkable map (the crowd's when it
/// has crowd agents, else one seeded at the robots' starts and lanes) and writes the PNG;
/// prints the regions' sizes. returns 0.
/// @throws ConfigError for a bad world or preset; Error when the PNG cannot be written.
int WriteNpcMap(const NpcMapOptions& options);

}  // namespace penumbra
