#include "penumbra/app/npc_map_command.h"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>

#include "penumbra/core/error.h"
#include "penumbra/core/output_file.h"
#include "penumbra/output/png_io.h"
#include "penumbra/physics/simulation.h"
#include "penumbra/session/npc_map.h"
#include "penumbra/session/session.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

ConfigError OutExists(const std::string& out) {
  return ConfigError("", 0, "--out",
                     "'" + out +
                         "' exists; expected a new file (never overwritten; --force replaces "
                         "it)");
}

// refuses an existing `out` (a link counts, followed or not) unless `force`
void CheckNewOut(const std::string& out, bool force) {
  std::error_code ec;
  if (!force && fs::exists(fs::symlink_status(out, ec))) throw OutExists(out);
}

// writes `bytes` to `out`: whole under a temporary sibling name, then given its name with
// link(2), which fails on an existing name (a file or a link made meanwhile is never
// replaced), or with --force renamed over it
void WriteNewFile(const std::string& out, const std::string& bytes, bool force) {
  if (force) {
    WriteFileAtomic(out, bytes);
    return;
  }
  const fs::path path = fs::absolute(out);
  const fs::path temp = path.parent_path() / ("." + path.filename().string() + ".npc-map-" +
                                              std::to_string(static_cast<long long>(::getpid())));
  WriteFileAtomic(temp, bytes);
  const int linked = ::link(temp.c_str(), path.c_str());
  const int err = errno;
  ::unlink(temp.c_str());
  if (linked == 0) return;
  if (err == EEXIST) throw OutExists(out);
  throw Error("cannot write " + out + ": " + std::strerror(err));
}

}  // namespace

int WriteNpcMap(const NpcMapOptions& options) {
  CheckNewOut(options.out, options.force);
  const WorldConfig world = LoadWorldFile(options.world_file);
  SessionOptions session_options;
  session_options.build_renderer = false;
  session_options.add_controllers = false;
  session_options.adversity = options.adversity;
  Session session(world, session_options);
  const EffectsStage& effects = session.effects();

  std::vector<Eigen::Vector3d> starts;
  std::vector<Eigen::Vector2d> robots;
  for (const ModelConfig& m : world.models)
    if (m.is_robot) {
      starts.push_back(m.pose.xyz);
      robots.push_back(m.pose.xyz.head<2>());
    }
  std::shared_ptr<const NpcMap> map = effects.npc_map();
  std::vector<Eigen::Vector2d> agents;
  if (map) {
    for (const CrowdAgentState& s : effects.crowd()->crowd().states())
      agents.push_back(s.position_W);
  } else {
    // no crowd: the map a crowd would walk, seeded at the robots' starts and the lanes
    const Simulation& sim = session.sim();
    const std::vector<Pose> X_WB = sim.Snapshot(Simulation::SnapshotContent::kPoses).X_WB;
    Eigen::Vector2d centre(0, 0);
    for (const Eigen::Vector2d& r : robots) centre += r / static_cast<double>(robots.size());
    std::vector<Eigen::Vector2d> seeds =
        robots.empty() ? std::vector<Eigen::Vector2d>{centre} : robots;
    std::vector<Eigen::Vector2d> vehicle_seeds = seeds;
    for (const CrowdSites::Lane& l : effects.sites().lanes)
      vehicle_seeds.insert(vehicle_seeds.end(), l.points_W.begin(), l.points_W.end());
    map = std::make_shared<const NpcMap>(
        sim.scene(), X_WB, NpcFloorHeight(sim.scene(), X_WB, starts), centre, seeds, vehicle_seeds);
  }
  const ImageU8 image = map->Draw(effects.sites(), robots, agents, options.pixels_per_cell);
  const std::vector<uint8_t> png = EncodePngRgb8(image);
  WriteNewFile(options.out, std::string(png.begin(), png.end()), options.force);
  std::printf(
      "npc map of %s: %d x %d cells of %.2f m, walkable by people %.1f m^2, by vehicles %.1f "
      "m^2; %zu areas, %zu lanes, %zu crowd agents -> %s (%d x %d px)\n",
      options.world_file.c_str(), map->person()->nx(), map->person()->ny(), map->person()->cell_m(),
      map->person()->walkable_cells() * map->person()->cell_m() * map->person()->cell_m(),
      map->vehicle()->walkable_cells() * map->vehicle()->cell_m() * map->vehicle()->cell_m(),
      effects.sites().areas.size(), effects.sites().lanes.size(), agents.size(),
      options.out.c_str(), image.width, image.height);
  return 0;
}

}  // namespace penumbra
