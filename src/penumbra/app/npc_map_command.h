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
  bool force = false;       ///< --force: an existing `out` (file or link) may be replaced
};

/// loads the world (no renderer, no controllers), builds its walkable map (the crowd's when it
/// has crowd agents, else one seeded at the robots' starts and lanes) and writes the PNG;
/// prints the regions' sizes. returns 0. an existing `out` (a file, or a link, which is never
/// followed) is refused before the world is loaded and again when the PNG is written (the PNG
/// is linked into place with link(2), which never replaces a name) unless options.force, which
/// replaces it (rename(2) over it: a link is replaced, not written through).
/// @throws ConfigError for a bad world or preset, and (key "--out") for an existing `out`
///         without force; Error when the PNG cannot be written.
int WriteNpcMap(const NpcMapOptions& options);

}  // namespace penumbra
