#pragma once
// the world file's `agents:` list: NPC people and vehicles on waypoint paths
// (effects/agent_path.h). keys of each entry (README "agents"):
//   name (required), type (person | forklift | cart, default person),
//   waypoints (required, >= 2 [x, y] in m), speed_m_s (0, 20], pause_sec [0, 3600],
//   start_delay_sec [0, 3600], route (loop | pingpong | once), floor_z (m),
//   height_m [0.5, 2.5] (person), motion (scripted | crowd), behaviour (avoid | ignore |
//   block), goals (patrol | random), clearance_m [0, 10], contact (bool, default false: a
//   crowd agent never moves into a robot and yields to it) (docs/npcs.md).

#include <vector>

#include "penumbra/config/param_reader.h"
#include "penumbra/effects/agent_path.h"

namespace penumbra {

/// reads and validates the `agents` list (`list` is the value of the `agents` key).
/// @param file the world file, named in errors
/// @throws ConfigError naming the file, line, key path ("agents[1].speed_m_s") and the
///         valid range: unknown keys, wrong types, < 2 waypoints, a negative or zero speed,
///         duplicate names.
std::vector<AgentConfig> ReadAgents(const ParamReader& list, const std::string& file);

}  // namespace penumbra
