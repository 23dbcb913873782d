#pragma once
// a run's crowd map as data (docs/npcs.md "The walkable map in the viewer"): what the
// viewer's scene view draws on the floor (the scene message's "npc_map") and what a run saves
// next to npc_map.png (npc_map.json).

#include <string>

#include "penumbra/session/session.h"

namespace penumbra {

/// the walkable map of the session's crowd with its sites, the robots' starts and the crowd
/// agents' positions now, or null when the session has no crowd (no `motion: crowd` agent):
/// {"cell_m": m, "min": [x, y] (world xy of the lower corner of cell (0, 0), m), "nx", "ny",
///  "z": the crowd's floor height, m, "cells": nx * ny characters, row iy = 0 (south) first,
///  each '0' blocked for people, '1' free but closer to an obstacle than a person's radius,
///  '2' walkable by people, '3' walkable by vehicles (NpcMap::Draw's colours, in its order),
///  "person_cells", "vehicle_cells": walkable cells of each region, "lanes": [{"name",
///  "points": [[x, y], ...]}], "areas": [{"name", "min": [x, y], "max": [x, y]}], "robots":
///  [[x, y], ...], "agents": [[x, y], ...]} (world frame, m).
/// returned as JSON text (one line; "null" without a crowd), so this header needs no JSON
/// library. reads the crowd's states: call before the run steps or on the loop thread.
std::string NpcMapJson(const Session& session);

}  // namespace penumbra
