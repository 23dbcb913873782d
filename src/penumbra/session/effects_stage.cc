#include "penumbra/session/effects_stage.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>

#include "penumbra/compose/agent_bodies.h"
#include "penumbra/core/error.h"
#include "penumbra/core/rng.h"
#include "penumbra/effects/agent_animation.h"
#include "penumbra/physics/simulation.h"
#include "penumbra/scene/scene_limits.h"
#include "penumbra/scene/sim_time.h"
#include "penumbra/session/floor_map.h"
#include "penumbra/world/yaml_reader.h"

namespace penumbra {
namespace {

// key of every draw of the preset planner (core/rng.h streams)
constexpr uint64_t kNpcStream = 0x4E5043A9E1ULL;

std::vector<Eigen::Vector3d> RobotStarts(const WorldConfig& world) {
  std::vector<Eigen::Vector3d> out;
  for (const ModelConfig& m : world.models)
    if (m.is_robot) out.push_back(m.pose.xyz);
  return out;
}

}  // namespace

std::vector<double> RobotStartYaws(const WorldConfig& world) {
  std::vector<double> out;
  for (const ModelConfig& m : world.models)
    if (m.is_robot) {
      const Eigen::Matrix3d R = m.pose.ToPose().linear();
      out.push_back(std::atan2(R(1, 0), R(0, 0)));
    }
  return out;
}

namespace {

// the longest stretch of `lane` (vertices snapped to `region` within 0.3 m, consecutive ones
// joined by walkable segments), or nothing when shorter than 3 m
std::vector<Eigen::Vector2d> DrivableStretch(const WalkableGrid& region,
                                             const std::vector<Eigen::Vector2d>& lane) {
  std::vector<Eigen::Vector2d> best, run;
  double best_len = 0, run_len = 0;
  const auto close_run = [&] {
    if (run.size() >= 2 && run_len > best_len) {
      best = run;
      best_len = run_len;
    }
    run.clear();
    run_len = 0;
  };
  for (const Eigen::Vector2d& p : lane) {
    const std::optional<Eigen::Vector2d> q = region.NearestWalkable(p);
    if (!q || (*q - p).norm() > 0.3) {
      close_run();
      continue;
    }
    if (!run.empty() && !region.SegmentWalkable(run.back(), *q)) close_run();
    if (!run.empty()) run_len += (*q - run.back()).norm();
    if (run.empty() || (*q - run.back()).norm() > 0.05) run.push_back(*q);
  }
  close_run();
  if (best_len < 3.0) best.clear();
  return best;
}

// a uniformly drawn walkable cell centre of `region` (rejection sampling, 4000 draws)
std::optional<Eigen::Vector2d> DrawWalkable(const WalkableGrid& region, Rng* rng) {
  const uint64_t cells = static_cast<uint64_t>(region.nx()) * region.ny();
  for (int k = 0; k < 4000; ++k) {
    const uint64_t c = rng->NextU64() % cells;
    const int ix = static_cast<int>(c % region.nx()), iy = static_cast<int>(c / region.nx());
    if (region.CellWalkable(ix, iy)) return region.CellCentre(ix, iy);
  }
  return std::nullopt;
}

// a `block` person's start: a walkable cell (of `people`, the area reachable from the robots)
// in front of the robot at `robot_W` facing `yaw` (rad about +z, 0 = +x), drawn from `rng`:
// first 2-6 m from it within 60 deg of its heading, else 1.5-8 m from it in its forward
// half-space; nothing when no draw is `free`. the person then starts where the robot is
// about to go instead of behind its route, where avoidance keeps it from passing the robot
template <typename Free>
std::optional<Eigen::Vector2d> BlockerStart(const WalkableGrid& people,
                                            const Eigen::Vector2d& robot_W, double yaw, Rng* rng,
                                            const Free& free) {
  struct Band {
    double min_m, max_m, half_angle;
  };
  for (const Band band : {Band{2.0, 6.0, M_PI / 3}, Band{1.5, 8.0, M_PI / 2}})
    for (int k = 0; k < 300; ++k) {
      const double d = band.min_m + (band.max_m - band.min_m) * rng->UniformD();
      const double a = yaw + band.half_angle * (2 * rng->UniformD() - 1);
      const Eigen::Vector2d p = robot_W + d * Eigen::Vector2d(std::cos(a), std::sin(a));
      if (people.Walkable(p) && free(p)) return p;
    }
  return std::nullopt;
}

// a `block` person's start when the robots' goal is known: a walkable cell (of `people`) near
// the route from the robot at `robot_W` to `goal_W` (the A* path on `people`, else the straight
// segment): the route's point at an arc length drawn in [min(2, L), min(6, L)] m (L the route's
// length), moved sideways by up to 1 m, drawn from `rng`; nothing when no draw is `free`.
// the person then starts where the robot is about to go, whichever way its goal lies
template <typename Free>
std::optional<Eigen::Vector2d> BlockerStartOnRoute(const WalkableGrid& people,
                                                   const Eigen::Vector2d& robot_W,
                                                   const Eigen::Vector2d& goal_W, Rng* rng,
                                                   const Free& free) {
  std::vector<Eigen::Vector2d> route = {robot_W, goal_W};
  if (std::optional<std::vector<Eigen::Vector2d>> path = people.Plan(robot_W, goal_W);
      path && path->size() >= 2)
    route = std::move(*path);
  double length = 0;
  for (size_t k = 1; k < route.size(); ++k) length += (route[k] - route[k - 1]).norm();
  if (length <= 0) return std::nullopt;
  const double max_m = std::min(6.0, length), min_m = std::min(2.0, max_m);
  for (int k = 0; k < 300; ++k) {
    double s = min_m + (max_m - min_m) * rng->UniformD();
    const double side = 2 * rng->UniformD() - 1;
    for (size_t j = 1; j < route.size(); ++j) {
      const Eigen::Vector2d seg = route[j] - route[j - 1];
      const double n = seg.norm();
      if (n <= 0 || (s > n && j + 1 < route.size())) {
        s -= n;
        continue;
      }
      const Eigen::Vector2d along = seg / n;
      const Eigen::Vector2d p =
          route[j - 1] + std::min(s, n) * along + side * Eigen::Vector2d(-along.y(), along.x());
      if (people.Walkable(p) && free(p)) return p;
      break;
    }
  }
  return std::nullopt;
}

// the preset's crowd (see the header's "npcs")
void PlanPresetNpcs(const AdversityPreset& preset, const NpcMap& map, const CrowdSites& sites,
                    const std::vector<Eigen::Vector3d>& robot_starts,
                    const std::vector<double>& robot_yaws, uint64_t seed,
                    std::vector<AgentConfig>* agents) {
  const WalkableGrid& people = *map.person();
  const WalkableGrid& vehicles = *map.vehicle();
  const auto away = [&](const Eigen::Vector2d& p, double d) {
    for (const Eigen::Vector3d& r : robot_starts)
      if ((p - r.head<2>()).norm() < d) return false;
    return true;
  };
  // points of interest: area centres and lane points, at least 1 m apart
  std::vector<Eigen::Vector2d> pois;
  const auto add_poi = [&](const Eigen::Vector2d& p, double snap) {
    const std::optional<Eigen::Vector2d> q = people.NearestWalkable(p);
    if (!q || (*q - p).norm() > snap) return;
    for (const Eigen::Vector2d& o : pois)
      if ((o - *q).norm() < 1.0) return;
    pois.push_back(*q);
  };
  for (const CrowdSites::Area& a : sites.areas) add_poi(0.5 * (a.min_W + a.max_W), 3.0);
  for (const CrowdSites::Lane& l : sites.lanes)
    for (const Eigen::Vector2d& p : l.points_W) add_poi(p, 0.5);
  if (pois.size() < 2) {
    Rng rng(HashKeys(seed, kNpcStream, 7));
    for (int k = 0; k < 200 && pois.size() < 6; ++k)
      if (const auto p = DrawWalkable(people, &rng)) {
        bool far = true;
        for (const Eigen::Vector2d& o : pois) far = far && (o - *p).norm() >= 2.0;
        if (far) pois.push_back(*p);
      }
  }
  // lanes people can walk
  std::vector<std::vector<Eigen::Vector2d>> walk_lanes;
  for (const CrowdSites::Lane& l : sites.lanes) {
    std::vector<Eigen::Vector2d> pts = DrivableStretch(people, l.points_W);
    if (!pts.empty()) walk_lanes.push_back(std::move(pts));
  }
  const auto base = [&](const std::string& name, AgentKind kind) {
    AgentConfig a;
    a.name = name;
    a.kind = kind;
    a.motion = AgentMotion::kCrowd;
    a.behaviour = preset.npc_behaviour;
    a.clearance_m = preset.npc_clearance_m;
    a.pause_sec = preset.npc_pause_sec;
    a.robot_contact = preset.npc_contact;
    a.floor_z = map.floor_z();
    return a;
  };
  // every start keeps the discs of the agents placed before it 0.3 m apart
  std::vector<std::pair<Eigen::Vector2d, double>> taken;
  const auto free_start = [&](const Eigen::Vector2d& p, double radius, double from_robot) {
    if (!away(p, from_robot)) return false;
    for (const auto& [q, r] : taken)
      if ((p - q).norm() < radius + r + 0.3) return false;
    return true;
  };
  const double person_r = KindModel(AgentKind::kPerson).disc_radius_m;
  const double vehicle_r = KindModel(AgentKind::kForklift).disc_radius_m;
  for (int i = 0; i < preset.npc_people; ++i) {
    const std::string name = "adversity_person" + std::to_string(i);
    Rng rng(HashKeys(seed, kNpcStream, 0, i));
    AgentConfig a = base(name, AgentKind::kPerson);
    a.speed_m_s = preset.npc_speed_m_s;
    // the preset's own spread of heights (the walkers' bodies read height_m only when given)
    a.height_m = 1.55 + 0.4 * rng.UniformD();
    a.height_given = true;
    const bool blocks = preset.npc_behaviour == AgentBehaviour::kBlock && !robot_starts.empty();
    if (i % 2 == 1 && !walk_lanes.empty() && !blocks) {
      std::vector<Eigen::Vector2d> lane = walk_lanes[(i / 2) % walk_lanes.size()];
      if ((i / 2 / walk_lanes.size()) % 2 == 1) std::reverse(lane.begin(), lane.end());
      if (!free_start(lane.front(), person_r, 1.5)) std::reverse(lane.begin(), lane.end());
      if (free_start(lane.front(), person_r, 1.5)) {
        a.waypoints = lane;
        a.route = AgentRoute::kPingPong;
        a.goals = AgentGoals::kPatrol;
        taken.emplace_back(lane.front(), person_r);
        agents->push_back(a);
        continue;
      }
    }
    if (pois.size() < 2) {
      spdlog::warn("adversity preset '{}': no points of interest for {}; left out", preset.name,
                   name);
      continue;
    }
    // the start: a free point of interest (from a drawn offset), else a free walkable cell;
    // a blocker's: in front of a robot (BlockerStart), else as the others'
    const size_t offset = rng.NextU64() % pois.size();
    std::optional<Eigen::Vector2d> start;
    if (blocks) {
      const size_t r = static_cast<size_t>(i) % robot_starts.size();
      const double yaw = r < robot_yaws.size() ? robot_yaws[r] : 0.0;
      const auto free = [&](const Eigen::Vector2d& p) { return free_start(p, person_r, 1.5); };
      if (preset.npc_block_goal) {
        start = BlockerStartOnRoute(people, robot_starts[r].head<2>(), *preset.npc_block_goal, &rng,
                                    free);
        if (!start)
          spdlog::warn(
              "adversity preset '{}': no free walkable cell near the robot's route to its goal "
              "for {}; it starts in front of the robot",
              preset.name, name);
      }
      if (!start) start = BlockerStart(people, robot_starts[r].head<2>(), yaw, &rng, free);
      if (!start)
        spdlog::warn(
            "adversity preset '{}': no free walkable cell in front of the robot for {}; "
            "it starts at a point of interest",
            preset.name, name);
    }
    for (size_t k = 0; k < pois.size() && !start; ++k)
      if (free_start(pois[(offset + k) % pois.size()], person_r, 1.5))
        start = pois[(offset + k) % pois.size()];
    for (int k = 0; k < 400 && !start; ++k)
      if (const auto p = DrawWalkable(people, &rng))
        if (free_start(*p, person_r, 1.5)) start = *p;
    if (!start) {
      spdlog::warn("adversity preset '{}': no free start for {}; left out", preset.name, name);
      continue;
    }
    a.waypoints.push_back(*start);
    for (size_t k = 0; k < pois.size(); ++k)
      if ((pois[(offset + k) % pois.size()] - *start).norm() > 0.05)
        a.waypoints.push_back(pois[(offset + k) % pois.size()]);
    a.goals = AgentGoals::kRandom;
    a.route = AgentRoute::kLoop;
    taken.emplace_back(*start, person_r);
    agents->push_back(a);
  }
  // then vehicles (people's places do not depend on how many vehicles there are: a live
  // change of the vehicle count keeps the people where they are)
  std::vector<AgentConfig> vehicle_agents;
  std::vector<std::vector<Eigen::Vector2d>> drive_lanes;
  for (const CrowdSites::Lane& l : sites.lanes) {
    if (!l.drivable) continue;
    std::vector<Eigen::Vector2d> pts = DrivableStretch(vehicles, l.points_W);
    if (!pts.empty()) drive_lanes.push_back(std::move(pts));
  }
  // vehicles drive only where the world says they may (a room is no place for a forklift)
  if (preset.npc_vehicles > 0 && !sites.any_drivable()) {
    spdlog::info(
        "adversity preset '{}': {} vehicle(s) left out: the world has no drivable area "
        "(vehicles drive only in a generated environment's drivable zones and lanes, "
        "docs/npcs.md)",
        preset.name, preset.npc_vehicles);
    return;
  }
  for (int j = 0; j < preset.npc_vehicles; ++j) {
    const std::string name = "adversity_forklift" + std::to_string(j);
    AgentConfig a = base(name, AgentKind::kForklift);
    a.speed_m_s = preset.npc_speed_m_s * 1.5;
    a.route = AgentRoute::kPingPong;
    a.goals = AgentGoals::kPatrol;
    std::vector<Eigen::Vector2d> lane;
    if (!drive_lanes.empty()) {
      lane = drive_lanes[j % drive_lanes.size()];
      if ((j / drive_lanes.size()) % 2 == 1) std::reverse(lane.begin(), lane.end());
      // the start: the first free point (every 0.25 m) of the lane's first half, from either end
      std::vector<Eigen::Vector2d> found;
      for (int side = 0; side < 2 && found.empty(); ++side) {
        if (side == 1) std::reverse(lane.begin(), lane.end());
        double total = 0;
        for (size_t k = 0; k + 1 < lane.size(); ++k) total += (lane[k + 1] - lane[k]).norm();
        double along = 0;
        for (size_t k = 0; k + 1 < lane.size() && found.empty() && along < 0.5 * total; ++k) {
          const double len = (lane[k + 1] - lane[k]).norm();
          for (double t = 0; t < len && found.empty() && along + t < 0.5 * total; t += 0.25) {
            const Eigen::Vector2d p = lane[k] + (lane[k + 1] - lane[k]) * (t / len);
            if (free_start(p, vehicle_r, 2.5)) {
              found.push_back(p);
              found.insert(found.end(), lane.begin() + k + 1, lane.end());
            }
          }
          along += len;
        }
      }
      lane = found;
    } else {
      // no drivable lane a forklift fits: a straight lane drawn from the seed inside the
      // drivable areas (checked every 0.25 m)
      Rng rng(HashKeys(seed, kNpcStream, 1, j));
      std::vector<Eigen::Vector2d> fallback;
      for (int k = 0; k < 200 && lane.empty(); ++k) {
        const auto p = DrawWalkable(vehicles, &rng), q = DrawWalkable(vehicles, &rng);
        if (!p || !q) break;
        const double len = (*q - *p).norm();
        if (len < 3.0 || len > 12.0 || !away(*p, 2.5) || !away(*q, 2.5) ||
            !vehicles.SegmentWalkable(*p, *q))
          continue;
        bool drivable = true;
        for (double t = 0; t <= len && drivable; t += 0.25)
          drivable = sites.Drivable(*p + (*q - *p) * (t / len), 0.0);
        if (!drivable || !sites.Drivable(*q, 0.0)) continue;
        if (free_start(*p, vehicle_r, 2.5))
          lane = {*p, *q};
        else if (free_start(*q, vehicle_r, 2.5))
          lane = {*q, *p};
        else if (fallback.empty())
          fallback = {*p, *q};  // clear of the robots only
      }
      // a small room: the lane may start by a person (the crowd separates them)
      if (lane.empty()) lane = fallback;
    }
    if (lane.size() < 2) {
      spdlog::warn("adversity preset '{}': no free lane a forklift fits for {}; left out",
                   preset.name, name);
      continue;
    }
    a.waypoints = lane;
    taken.emplace_back(lane.front(), vehicle_r);
    vehicle_agents.push_back(a);
  }
  agents->insert(agents->end(), vehicle_agents.begin(), vehicle_agents.end());
}

// appends an effect named `name` of type P (default parameters, no region) to `effects`;
// returns its parameters (valid until the next append).
template <typename P>
P& AppendEffect(std::vector<EffectConfig>* effects, std::string name) {
  EffectConfig& e = effects->emplace_back();
  e.name = std::move(name);
  return e.params.emplace<P>();
}

}  // namespace

void PlanAdversityPreset(const AdversityPreset& preset, const SceneDescription& scene,
                         const std::vector<Pose>& X_WB,
                         const std::vector<Eigen::Vector3d>& robot_starts,
                         const std::vector<double>& robot_yaws, uint64_t seed,
                         std::vector<EffectConfig>* effects, std::vector<AgentConfig>* agents,
                         const CrowdSites& sites) {
  Eigen::Vector2d centre(0, 0);
  for (const Eigen::Vector3d& r : robot_starts)
    centre += r.head<2>() / static_cast<double>(robot_starts.size());
  // the floor: the highest static upward plane at or below the lowest robot, else its z
  const double floor_z = NpcFloorHeight(scene, X_WB, robot_starts, /*with_slabs=*/false);
  FloorMap map(scene, X_WB, floor_z, centre);
  const Eigen::Vector2d flood_seed =
      robot_starts.empty() ? centre : Eigen::Vector2d(robot_starts.front().head<2>());
  // the robots' area: the free floor reachable from the first robot
  map.Flood(flood_seed, 0.4);
  Eigen::Vector2d area_lo = map.min_W(), area_hi = map.max_W();
  map.ReachableBounds(&area_lo, &area_hi);

  if (preset.fog_mor_m) {
    FogParams& p = AppendEffect<FogParams>(effects, "adversity_fog");
    p.extinction.mor_m = *preset.fog_mor_m;
    p.height_falloff_per_m = preset.fog_height_falloff_per_m;
    p.base_height_m = floor_z + 1.0;
  }
  if (preset.dust_mor_m) {
    DustParams& p = AppendEffect<DustParams>(effects, "adversity_dust");
    p.extinction.mor_m = *preset.dust_mor_m;
  }
  if (preset.smoke_sigma_t_per_m) {
    SmokeParams& p = AppendEffect<SmokeParams>(effects, "adversity_smoke");
    p.mode = SmokeParams::Mode::kNoise;
    p.density_scale_per_m = *preset.smoke_sigma_t_per_m;
    p.coverage = preset.smoke_coverage;
    p.wind_m_s = Eigen::Vector3d(0.3, 0, 0);
    const Eigen::Vector2d mid = 0.5 * (area_lo + area_hi);
    const Eigen::Vector2d half = 0.5 * preset.smoke_extent_fraction * (area_hi - area_lo);
    BoxRegion box;
    box.min_W = Eigen::Vector3d(mid.x() - half.x(), mid.y() - half.y(), floor_z);
    box.max_W =
        Eigen::Vector3d(mid.x() + half.x(), mid.y() + half.y(), floor_z + preset.smoke_height_m);
    effects->back().region = box;
  }
  if (preset.rain_rate_mm_h) {
    RainParams& p = AppendEffect<RainParams>(effects, "adversity_rain");
    p.rate_mm_h = *preset.rain_rate_mm_h;
  }
  if (preset.snow_rate_mm_h) {
    SnowParams& p = AppendEffect<SnowParams>(effects, "adversity_snow");
    p.rate_mm_h = *preset.snow_rate_mm_h;
  }
  if (preset.light_scale != 1.0) {
    LightEventParams& p = AppendEffect<LightEventParams>(effects, "adversity_dim");
    p.light = "*";
    p.mode = LightEventParams::Mode::kBlackout;
    p.min_scale = std::min(preset.light_scale, 0.999);
    p.recovery_sec = 0;
  }
  if (preset.flicker_depth > 0) {
    LightEventParams& p = AppendEffect<LightEventParams>(effects, "adversity_flicker");
    p.light = "*";
    p.mode = LightEventParams::Mode::kFlicker;
    p.depth = preset.flicker_depth;
    p.frequency_hz = preset.flicker_hz;
  }

  // NPCs: a crowd on the walkable map seeded at the robots' starts (and the lanes, for vehicles)
  if (preset.npc_people + preset.npc_vehicles > 0) {
    std::vector<Eigen::Vector2d> person_seeds{flood_seed};
    for (const Eigen::Vector3d& r : robot_starts) person_seeds.push_back(r.head<2>());
    std::vector<Eigen::Vector2d> vehicle_seeds = person_seeds;
    for (const CrowdSites::Lane& l : sites.lanes)
      vehicle_seeds.insert(vehicle_seeds.end(), l.points_W.begin(), l.points_W.end());
    // the NPCs' floor also knows floor slabs (a generated building's floor box)
    const NpcMap npc_map(scene, X_WB, NpcFloorHeight(scene, X_WB, robot_starts), centre,
                         person_seeds, vehicle_seeds);
    PlanPresetNpcs(preset, npc_map, sites, robot_starts, robot_yaws, seed, agents);
  }
}

std::pair<int, int> LiveNpcReserve() {
  int people = 0, vehicles = 0;
  for (const char* name : {"minor", "major"}) {
    const AdversityPreset p = LoadAdversityPreset(ResolveAdversitySpec(name, "", "", 0));
    people = std::max(people, p.npc_people);
    vehicles = std::max(vehicles, p.npc_vehicles);
  }
  return {people, vehicles};
}

EffectsStage::EffectsStage(const WorldConfig& world, ComposedScene* composed,
                           const std::string& adversity_override, bool reserve_live_npcs,
                           CrowdSites sites)
    : effects_(world.effects),
      agents_(world.agents),
      seed_(world.seed),
      world_file_(world.file),
      world_agents_(world.agents.size()),
      robot_starts_(RobotStarts(world)),
      robot_yaws_(RobotStartYaws(world)),
      sites_(std::move(sites)) {
  for (const ModelConfig& m : world.models)
    if (m.is_robot) robots_.push_back(m);
  ValidateAgentsOrThrow(agents_, world.file);
  std::string spec = world.adversity;
  std::string spec_file = world.file;
  int spec_line = world.adversity_line;
  if (!adversity_override.empty()) {
    // a bad command-line value is the flag's, not the world file's `adversity` line (errors
    // inside a preset file keep that file's name and line)
    try {
      spec = ResolveAdversitySpec(adversity_override, "", "", 0);
    } catch (const ConfigError& e) {
      if (!e.file().empty()) throw;
      throw ConfigError("", 0, "--adversity", e.problem());
    }
    spec_file.clear();
    spec_line = 0;
  }
  if (!spec.empty()) preset_ = LoadAdversityPreset(spec, spec_file, spec_line);

  // the preset's regions and NPC paths need the static scene at the start, before the NPCs'
  // bodies exist, and Penumbra adds no bodies to a compiled model, so a world with a
  // preset compiles its composed document twice, here (a probe, without agents) and for the
  // run. without a preset it compiles once; the world's own agents are checked against
  // the run's model in Attach.
  if (preset_ && !preset_->empty()) {
    const Simulation probe = Simulation::LoadFromString(composed->Xml(), world.timestep_sec);
    PlanAdversityPreset(*preset_, probe.scene(), probe.Snapshot().X_WB, robot_starts_, robot_yaws_,
                        world.seed, &effects_, &agents_, sites_);
  }
  ValidateEffectsOrThrow(effects_, world.file);
  ValidateAgentsOrThrow(agents_, world.file);  // the preset's agents too
  std::vector<MocapBodySpec> bodies = AgentBodySpecs(agents_, seed_);
  if (reserve_live_npcs) {
    // parked bodies named as PlanAdversityPreset names its NPCs, for those it did not plan
    const auto [people, vehicles] = LiveNpcReserve();
    const Eigen::Vector3d start =
        robot_starts_.empty() ? Eigen::Vector3d::Zero() : robot_starts_.front();
    for (int kind = 0; kind < 2; ++kind)
      for (int i = 0; i < (kind == 0 ? people : vehicles); ++i) {
        AgentConfig a;
        a.name =
            std::string("adversity_") + (kind == 0 ? "person" : "forklift") + std::to_string(i);
        if (std::any_of(agents_.begin(), agents_.end(),
                        [&](const AgentConfig& b) { return b.name == a.name; }))
          continue;
        a.kind = kind == 0 ? AgentKind::kPerson : AgentKind::kForklift;
        a.waypoints = {start.head<2>(), start.head<2>() + Eigen::Vector2d(1, 0)};
        a.route = AgentRoute::kLoop;
        reserved_.push_back(a);
      }
    std::vector<MocapBodySpec> parked = AgentBodySpecs(reserved_, seed_);
    for (size_t i = 0; i < parked.size(); ++i) parked[i].X_WB = AgentParkedPose(reserved_[i]);
    bodies.insert(bodies.end(), parked.begin(), parked.end());
  }
  // the world's agents were counted when read; with a preset's NPCs and a live reserve, here
  // (scene/scene_limits.h)
  if (bodies.size() > static_cast<size_t>(kMaxAgents)) {
    const size_t added = bodies.size() - world_agents_;
    throw ConfigError(
        world.file, 0, spec.empty() || added == reserved_.size() ? "agents" : "adversity",
        std::to_string(bodies.size()) + " agents (" + std::to_string(world_agents_) +
            " in the world file, " + std::to_string(added - reserved_.size()) +
            " from the adversity preset, " + std::to_string(reserved_.size()) +
            " reserved for live presets); expected at most " + std::to_string(kMaxAgents) +
            " (MuJoCo's collision detection needs memory that grows with the square of the bodies; "
            "each agent is several)");
  }
  AddAgentBodies(bodies, world.file, composed);
}

EffectsStage::~EffectsStage() = default;

bool AgentMayTouchRobot(const AgentConfig& agent) {
  return agent.motion == AgentMotion::kScripted || agent.robot_contact ||
         agent.behaviour == AgentBehaviour::kBlock;
}

std::vector<AgentConfig> TouchingAgentsWithout(const std::vector<AgentConfig>& agents,
                                               const std::vector<std::string>& mocap_bodies) {
  std::vector<AgentConfig> out;
  for (const AgentConfig& a : agents)
    if (AgentMayTouchRobot(a) && std::find(mocap_bodies.begin(), mocap_bodies.end(),
                                           AgentBodyName(a.name)) == mocap_bodies.end())
      out.push_back(a);
  return out;
}

WalkerAppearance AgentAppearance(const AgentConfig& agent, uint64_t seed) {
  return WalkerAppearanceOf(seed, agent.name, agent.height_given ? agent.height_m : 0.0);
}

std::vector<MocapBodySpec> AgentBodySpecs(const std::vector<AgentConfig>& agents, uint64_t seed) {
  std::vector<MocapBodySpec> specs;
  for (const AgentConfig& a : agents) {
    MocapBodySpec s;
    s.name = a.name;
    switch (a.kind) {
      case AgentKind::kPerson:
        s.shape = MocapBodySpec::Shape::kPerson;
        break;
      case AgentKind::kForklift:
        s.shape = MocapBodySpec::Shape::kForklift;
        break;
      case AgentKind::kCart:
        s.shape = MocapBodySpec::Shape::kCart;
        break;
    }
    const WalkerAppearance look = AgentAppearance(a, seed);
    s.height_m = look.height_m;
    s.shirt_rgb = {look.shirt.r, look.shirt.g, look.shirt.b};
    s.trousers_rgb = {look.trousers.r, look.trousers.g, look.trousers.b};
    s.skin_rgb = {look.skin.r, look.skin.g, look.skin.b};
    s.X_WB = AgentPath(a).X_WA(0.0);
    specs.push_back(std::move(s));
  }
  return specs;
}

Pose AgentParkedPose(const AgentConfig& agent) {
  Pose X = AgentPath(agent).X_WA(0.0);
  X.translation().z() -= 100.0;
  return X;
}

void EffectsStage::Attach(Simulation* sim) {
  // the world's agents must walk inside the world: the static geometry's plan-view box + 1 m
  // (agent bodies are mocap, never static, so they do not widen it)
  if (world_agents_ > 0) {
    Eigen::Vector2d centre(0, 0);
    for (const Eigen::Vector3d& r : robot_starts_)
      centre += r.head<2>() / static_cast<double>(robot_starts_.size());
    const FloorMap map(sim->scene(), sim->Snapshot(Simulation::SnapshotContent::kPoses).X_WB, 0.0,
                       centre);
    if (map.has_static_bounds()) {
      const Eigen::Vector2d lo = map.static_min_W() - Eigen::Vector2d(1, 1);
      const Eigen::Vector2d hi = map.static_max_W() + Eigen::Vector2d(1, 1);
      for (size_t i = 0; i < world_agents_; ++i)
        for (size_t j = 0; j < agents_[i].waypoints.size(); ++j) {
          const Eigen::Vector2d& p = agents_[i].waypoints[j];
          if ((p.array() < lo.array()).any() || (p.array() > hi.array()).any())
            throw ConfigError(
                world_file_, agents_[i].line,
                "agents[" + std::to_string(i) + "].waypoints[" + std::to_string(j) + "]",
                "[" + FormatNumber(p.x()) + ", " + FormatNumber(p.y()) +
                    "] lies outside the world; expected x in [" + FormatNumber(lo.x()) + ", " +
                    FormatNumber(hi.x()) + "], y in [" + FormatNumber(lo.y()) + ", " +
                    FormatNumber(hi.y()) + "] m (the static geometry's extent + 1 m)");
        }
    }
  }
  // the root and part bodies of every agent follow its animator (effects/agent_animation.h)
  // over the root's pose: its crowd's (motion: crowd, session/crowd_runner.h), its path's, or
  // parked; a live change gives an agent whose motion changed a fresh animator
  sim_ = sim;
  episode_start_ = sim->controller_episode_start();
  crowd_ = MakeCrowd(agents_, 0.0);
  size_t crowd_index = 0;
  const auto attach = [&](const AgentConfig& a, bool parked_reserve) {
    auto slot = std::make_shared<AgentSlot>();
    slot->kind = a.kind;
    slot->height_m = AgentAppearance(a, seed_).height_m;
    slot->parked = AgentParkedPose(a);
    std::shared_ptr<const AgentPath> path;
    if (!parked_reserve && a.motion == AgentMotion::kCrowd && crowd_) {
      slot->crowd = crowd_;
      slot->crowd_index = crowd_index++;
    } else if (!parked_reserve) {
      path = std::make_shared<const AgentPath>(a);
    }
    slot->Follow(std::move(path));
    // t is the episode's time (Simulation::AddMocapDriver); a new episode restarts the agents
    sim->AddMocapDriver(AgentBodyName(a.name), [this, slot](double t) {
      FollowEpisode();
      return slot->animator->Poses(t)[0];
    });
    const std::vector<std::string> parts = AgentPartNames(a.kind);
    for (size_t j = 0; j < parts.size(); ++j)
      sim->AddMocapDriver(AgentPartBodyName(a.name, parts[j]), [this, slot, j](double t) {
        FollowEpisode();
        return slot->animator->Poses(t)[j + 1];
      });
    body_names_.push_back(a.name);
    slots_.push_back(std::move(slot));
  };
  for (const AgentConfig& a : agents_) attach(a, false);
  for (const AgentConfig& a : reserved_) attach(a, true);
}

void EffectsStage::AgentSlot::Follow(std::shared_ptr<const AgentPath> new_path) {
  path = std::move(new_path);
  const std::shared_ptr<const AgentPath> p = path;
  const std::shared_ptr<CrowdRunner> c = crowd;
  const size_t ci = crowd_index;
  const Pose rest = parked;
  animator = std::make_shared<AgentAnimator>(kind, height_m, [p, c, ci, rest](double t) {
    if (c) return c->X_WA(ci, t);
    return p ? p->X_WA(t) : rest;
  });
}

std::shared_ptr<CrowdRunner> EffectsStage::MakeCrowd(const std::vector<AgentConfig>& agents,
                                                     double start_sec,
                                                     std::shared_ptr<const NpcMap> map) {
  std::vector<AgentConfig> crowd;
  for (const AgentConfig& a : agents)
    if (a.motion == AgentMotion::kCrowd) crowd.push_back(a);
  if (crowd.empty() || !sim_) return nullptr;
  Eigen::Vector2d centre(0, 0);
  for (const Eigen::Vector3d& r : robot_starts_)
    centre += r.head<2>() / static_cast<double>(robot_starts_.size());
  std::vector<Eigen::Vector2d> person_seeds{
      robot_starts_.empty() ? centre : Eigen::Vector2d(robot_starts_.front().head<2>())};
  for (const Eigen::Vector3d& r : robot_starts_) person_seeds.push_back(r.head<2>());
  std::vector<Eigen::Vector2d> vehicle_seeds = person_seeds;
  for (const CrowdSites::Lane& l : sites_.lanes)
    vehicle_seeds.insert(vehicle_seeds.end(), l.points_W.begin(), l.points_W.end());
  for (const AgentConfig& a : crowd) {
    std::vector<Eigen::Vector2d>& seeds = IsVehicle(a.kind) ? vehicle_seeds : person_seeds;
    seeds.insert(seeds.end(), a.waypoints.begin(), a.waypoints.end());
  }
  const double floor_z = crowd.front().floor_z;
  npc_map_ = map ? std::move(map)
                 : std::make_shared<const NpcMap>(
                       sim_->scene(), sim_->Snapshot(Simulation::SnapshotContent::kPoses).X_WB,
                       floor_z, centre, person_seeds, vehicle_seeds);
  auto sim =
      std::make_unique<CrowdSim>(std::move(crowd), npc_map_->person(), npc_map_->vehicle(), seed_);
  auto runner = std::make_shared<CrowdRunner>(std::move(sim), sim_, CrowdRobotsOf(robots_, *sim_),
                                              floor_z, start_sec);
  if (decision_sink_) runner->set_decision_sink(EpisodeDecisionSink());
  return runner;
}

std::function<void(double, const std::string&)> EffectsStage::EpisodeDecisionSink() {
  // the crowd runs on the episode's time; its decisions are logged at sim time
  return [this](double t, const std::string& payload) {
    if (decision_sink_) decision_sink_(episode_start_sec_ + t, payload);
  };
}

void EffectsStage::set_crowd_decision_sink(std::function<void(double, const std::string&)> sink) {
  decision_sink_ = std::move(sink);
  if (crowd_) crowd_->set_decision_sink(EpisodeDecisionSink());
}

void EffectsStage::FollowEpisode() {
  if (!sim_ || sim_->controller_episode_start() == episode_start_) return;
  episode_start_ = sim_->controller_episode_start();
  episode_start_sec_ = SimTimeOfStep(episode_start_, sim_->timestep());
  // every agent back to its start: the crowd as just constructed (its map kept: it depends on
  // the static scene and the agents alone), paths from their time 0, fresh animators
  std::vector<std::shared_ptr<const AgentPath>> paths(slots_.size());
  std::vector<size_t> crowd_slot;
  for (const AgentConfig& a : agents_) {
    const auto it = std::find(body_names_.begin(), body_names_.end(), a.name);
    if (it == body_names_.end()) continue;
    if (a.motion == AgentMotion::kCrowd)
      crowd_slot.push_back(it - body_names_.begin());
    else
      paths[it - body_names_.begin()] = std::make_shared<const AgentPath>(a);
  }
  crowd_ = MakeCrowd(agents_, 0.0, npc_map_);
  for (size_t i = 0; i < slots_.size(); ++i) {
    AgentSlot& s = *slots_[i];
    s.crowd = nullptr;
    s.crowd_index = 0;
    for (size_t k = 0; k < crowd_slot.size(); ++k)
      if (crowd_slot[k] == i && crowd_) {
        s.crowd = crowd_;
        s.crowd_index = k;
      }
    s.Follow(s.crowd ? nullptr : paths[i]);
  }
}

void EffectsStage::Replace(std::vector<EffectConfig> effects, std::vector<AgentConfig> agents,
                           std::optional<AdversityPreset> preset,
                           std::unique_ptr<EffectsEngine> engine) {
  std::vector<std::shared_ptr<const AgentPath>> paths(slots_.size());
  std::vector<size_t> crowd_slot;  // slot of each crowd agent, in the crowd's order
  for (const AgentConfig& a : agents) {
    const auto it = std::find(body_names_.begin(), body_names_.end(), a.name);
    if (it == body_names_.end())
      throw ConfigError("", 0, "npcs",
                        "agent '" + a.name +
                            "' has no body in this run (bodies are not added to a loaded model); "
                            "expected at most the NPCs the run started with");
    if (a.motion == AgentMotion::kCrowd)
      crowd_slot.push_back(it - body_names_.begin());
    else
      paths[it - body_names_.begin()] = std::make_shared<const AgentPath>(a);
  }
  // crowd agents the running crowd has, unchanged, go on in it (the others in it leave it);
  // else the new crowd starts now (its goals from the seed, its time from now)
  bool keep = crowd_ != nullptr;
  std::vector<size_t> index_in_crowd;
  for (size_t k = 0; keep && k < crowd_slot.size(); ++k) {
    const std::string& name = body_names_[crowd_slot[k]];
    const std::vector<AgentConfig>& running = crowd_->crowd().agents();
    size_t found = running.size();
    for (size_t m = 0; m < running.size(); ++m)
      if (running[m].name == name) found = m;
    const auto same = [](const AgentConfig& x, const AgentConfig& y) {
      return x.kind == y.kind && x.waypoints == y.waypoints && x.speed_m_s == y.speed_m_s &&
             x.pause_sec == y.pause_sec && x.route == y.route && x.goals == y.goals &&
             x.behaviour == y.behaviour && x.clearance_m == y.clearance_m &&
             x.floor_z == y.floor_z && x.robot_contact == y.robot_contact;
    };
    const auto it = std::find_if(agents.begin(), agents.end(),
                                 [&](const AgentConfig& a) { return a.name == name; });
    keep = found < running.size() && same(running[found], *it);
    index_in_crowd.push_back(found);
  }
  std::shared_ptr<CrowdRunner> crowd;
  if (keep) {
    crowd = crowd_;
    for (size_t m = 0; m < crowd->crowd().agents().size(); ++m)
      crowd->SetActive(
          m, std::find(index_in_crowd.begin(), index_in_crowd.end(), m) != index_in_crowd.end());
  } else {
    crowd = MakeCrowd(agents, sim_ ? sim_->time() - episode_start_sec_ : 0.0);
    index_in_crowd.clear();
    for (size_t k = 0; k < crowd_slot.size(); ++k) index_in_crowd.push_back(k);
  }
  // every slot follows its new source; an agent that goes on in the same crowd keeps its
  // animator (its limbs' motion state), the others get a fresh one
  for (size_t i = 0; i < slots_.size(); ++i) {
    AgentSlot& s = *slots_[i];
    std::shared_ptr<CrowdRunner> c;
    size_t ci = 0;
    for (size_t k = 0; k < crowd_slot.size(); ++k)
      if (crowd_slot[k] == i) {
        c = crowd;
        ci = index_in_crowd[k];
      }
    const bool same_crowd_agent = c && s.crowd == c && s.crowd_index == ci && s.animator;
    s.crowd = c;
    s.crowd_index = ci;
    if (!same_crowd_agent) s.Follow(paths[i]);
  }
  crowd_ = crowd;
  std::lock_guard<std::mutex> lock(mu_);
  effects_ = std::move(effects);
  agents_ = std::move(agents);
  preset_ = std::move(preset);
  engine_ = std::move(engine);
}

SceneDescription EffectsStage::Bind(SceneDescription scene) {
  // every body of an agent (root and parts), the parked reserve's too
  for (const std::vector<AgentConfig>* list : {&agents_, &reserved_})
    for (const AgentConfig& a : *list)
      for (Geom& g : scene.geoms)
        if (g.body > 0 && g.semantic_class == 0 && IsAgentBodyOf(scene.bodies[g.body].name, a.name))
          g.semantic_class = AgentSemanticClass(a.kind);
  if (!effects_.empty()) engine_ = std::make_unique<EffectsEngine>(effects_, seed_, scene);
  return scene;
}

std::shared_ptr<const EffectsFrame> EffectsStage::Evaluate(const WorldSnapshot& snapshot,
                                                           const Eigen::Vector3d& viewer_W) {
  if (!engine_) return nullptr;
  // the episode's time (WorldSnapshot::episode_start_step): effects restart with the episode
  const double t =
      snapshot.episode_start_step > 0 && sim_
          ? SimTimeOfStep(snapshot.step - snapshot.episode_start_step, sim_->timestep())
          : snapshot.time_sec;
  return engine_->Evaluate(t, viewer_W, &snapshot.X_WB);
}

std::vector<std::string> EffectsStage::EffectLabels() const {
  std::lock_guard<std::mutex> lock(mu_);
  std::vector<std::string> out;
  for (const EffectConfig& e : effects_) out.push_back(e.name + ": " + e.type_name());
  return out;
}

std::vector<std::string> EffectsStage::AgentLabels() const {
  std::lock_guard<std::mutex> lock(mu_);
  std::vector<std::string> out;
  for (const AgentConfig& a : agents_) out.push_back(a.name + ": " + AgentKindName(a.kind));
  return out;
}

std::string EffectsStage::PresetLabel() const {
  std::lock_guard<std::mutex> lock(mu_);
  return preset_ ? preset_->name + " (" + preset_->file + ")" : std::string();
}

}  // namespace penumbra
