#include "penumbra/session/npc_map_json.h"

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace penumbra {

namespace {

nlohmann::json NpcMapJsonValue(const Session& session) {
  using nlohmann::json;
  const std::shared_ptr<const NpcMap> map = session.effects().npc_map();
  if (!map) return nullptr;
  const WalkableGrid& g = *map->person();
  const WalkableGrid& v = *map->vehicle();
  std::string cells(static_cast<size_t>(g.nx()) * g.ny(), '1');
  for (int iy = 0; iy < g.ny(); ++iy)
    for (int ix = 0; ix < g.nx(); ++ix) {
      char c = '1';
      if (g.CellBlocked(ix, iy)) c = '0';
      if (g.CellWalkable(ix, iy)) c = '2';
      if (v.CellWalkable(ix, iy)) c = '3';
      cells[static_cast<size_t>(iy) * g.nx() + ix] = c;
    }
  const auto xy = [](const Eigen::Vector2d& p) { return json::array({p.x(), p.y()}); };
  json lanes = json::array(), areas = json::array(), robots = json::array(), agents = json::array();
  for (const CrowdSites::Lane& l : session.effects().sites().lanes) {
    json points = json::array();
    for (const Eigen::Vector2d& p : l.points_W) points.push_back(xy(p));
    lanes.push_back({{"name", l.name}, {"points", points}});
  }
  for (const CrowdSites::Area& a : session.effects().sites().areas)
    areas.push_back({{"name", a.name}, {"min", xy(a.min_W)}, {"max", xy(a.max_W)}});
  for (const ModelConfig& m : session.world().models)
    if (m.is_robot) robots.push_back(xy(m.pose.xyz.head<2>()));
  if (const std::shared_ptr<const CrowdRunner> crowd = session.effects().crowd())
    for (const CrowdAgentState& a : crowd->crowd().states()) agents.push_back(xy(a.position_W));
  return {{"cell_m", g.cell_m()},
          {"min", xy(g.min_W())},
          {"nx", g.nx()},
          {"ny", g.ny()},
          {"z", map->floor_z()},
          {"cells", cells},
          {"person_cells", g.walkable_cells()},
          {"vehicle_cells", v.walkable_cells()},
          {"lanes", lanes},
          {"areas", areas},
          {"robots", robots},
          {"agents", agents}};
}

}  // namespace

std::string NpcMapJson(const Session& session) { return NpcMapJsonValue(session).dump(); }

}  // namespace penumbra
