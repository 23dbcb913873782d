#include "penumbra/session/effects_stage.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>

#include "penumbra/compose/agent_bodies.h"
#include "penumbra/core/error.h"
#include "penumbra/core/rng.h"
#include "penumbra/effects/agent_animation.h"
#include "penumbra/physics/simulation.h"
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

// a closed loop of 3-4 waypoints for one NPC, or nothing after 200 draws
std::optional<std::vector<Eigen::Vector2d>> DrawLoop(const FloorMap& map, uint64_t stream,
                                                     double clearance,
                                                     const std::vector<Eigen::Vector3d>& robots) {
  Rng rng(stream);
  const auto away_from_robots = [&](const Eigen::Vector2d& p) {
    for (const Eigen::Vector3d& r : robots)
      if ((p - r.head<2>()).norm() < 1.5) return false;
    return true;
  };
  for (int attempt = 0; attempt < 200; ++attempt) {
    const int n = 3 + static_cast<int>(rng.NextU64() % 2);
    std::vector<Eigen::Vector2d> pts;
    bool ok = true;
    for (int i = 0; i < n && ok; ++i) {
      Eigen::Vector2d p;
      ok =
          map.RandomFreePoint(rng.NextU64(), &p) && away_from_robots(p) && map.IsFree(p, clearance);
      if (ok && !pts.empty())
        ok = (p - pts.back()).norm() > 1.0 && map.SegmentFree(pts.back(), p, clearance);
      if (ok) pts.push_back(p);
    }
    if (ok && map.SegmentFree(pts.back(), pts.front(), clearance)) return pts;
  }
  return std::nullopt;
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
                         const std::vector<Eigen::Vector3d>& robot_starts, uint64_t seed,
                         std::vector<EffectConfig>* effects, std::vector<AgentConfig>* agents) {
  double lowest = 0;
  Eigen::Vector2d centre(0, 0);
  if (!robot_starts.empty()) {
    lowest = robot_starts.front().z();
    for (const Eigen::Vector3d& r : robot_starts) {
      lowest = std::min(lowest, r.z());
      centre += r.head<2>() / static_cast<double>(robot_starts.size());
    }
  }
  // the floor: the highest static upward plane at or below the lowest robot, else its z
  double floor_z = -1e300;
  for (const Geom& g : scene.geoms) {
    if (g.shape != GeomShape::kPlane || !scene.bodies[g.body].is_static) continue;
    const Pose X_WG =
        (g.body < static_cast<int>(X_WB.size()) ? X_WB[g.body] : Pose::Identity()) * g.X_BG;
    if (X_WG.linear()(2, 2) < 0.99) continue;
    const double z = X_WG.translation().z();
    if (z <= lowest + 0.05) floor_z = std::max(floor_z, z);
  }
  if (floor_z == -1e300) floor_z = lowest;
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

  // NPCs: people first, then vehicles; each on its own random stream
  for (int kind = 0; kind < 2; ++kind) {
    const int count = kind == 0 ? preset.npc_people : preset.npc_vehicles;
    if (count == 0) continue;
    const double clearance = kind == 0 ? 0.4 : 1.2;
    map.Flood(flood_seed, clearance);
    for (int i = 0; i < count; ++i) {
      const std::string name =
          std::string("adversity_") + (kind == 0 ? "person" : "forklift") + std::to_string(i);
      const auto loop = DrawLoop(map, HashKeys(seed, kNpcStream, kind, i), clearance, robot_starts);
      if (!loop) {
        spdlog::warn("adversity preset '{}': no free path found for {}; left out", preset.name,
                     name);
        continue;
      }
      AgentConfig a;
      a.name = name;
      a.kind = kind == 0 ? AgentKind::kPerson : AgentKind::kForklift;
      a.waypoints = *loop;
      a.speed_m_s = preset.npc_speed_m_s * (kind == 0 ? 1.0 : 1.5);
      a.pause_sec = preset.npc_pause_sec;
      a.route = AgentRoute::kLoop;
      a.floor_z = floor_z;
      agents->push_back(a);
    }
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
                           const std::string& adversity_override, bool reserve_live_npcs)
    : effects_(world.effects),
      agents_(world.agents),
      seed_(world.seed),
      world_file_(world.file),
      world_agents_(world.agents.size()),
      robot_starts_(RobotStarts(world)) {
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
  // bodies exist: MuJoCo 2.2.2 cannot add bodies to a compiled model, so a world with a
  // preset compiles its composed document twice, here (a probe, without agents) and for the
  // run. without a preset it compiles once; the world's own agents are checked against
  // the run's model in Attach.
  if (preset_ && !preset_->empty()) {
    const Simulation probe = Simulation::LoadFromString(composed->Xml(), world.timestep_sec);
    PlanAdversityPreset(*preset_, probe.scene(), probe.Snapshot().X_WB, robot_starts_, world.seed,
                        &effects_, &agents_);
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
  AddAgentBodies(bodies, world.file, composed);
}

EffectsStage::~EffectsStage() = default;

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
  // the root and part bodies of every agent follow its animator (effects/agent_animation.h),
  // which a live change replaces with the new path's
  const auto attach = [&](const AgentConfig& a, std::shared_ptr<const AgentPath> path) {
    auto slot = std::make_shared<AgentSlot>();
    slot->kind = a.kind;
    slot->height_m = AgentAppearance(a, seed_).height_m;
    slot->parked = AgentParkedPose(a);
    slot->Follow(std::move(path));
    sim->AddMocapDriver(AgentBodyName(a.name),
                        [slot](double t) { return slot->animator->Poses(t)[0]; });
    const std::vector<std::string> parts = AgentPartNames(a.kind);
    for (size_t j = 0; j < parts.size(); ++j)
      sim->AddMocapDriver(AgentPartBodyName(a.name, parts[j]),
                          [slot, j](double t) { return slot->animator->Poses(t)[j + 1]; });
    body_names_.push_back(a.name);
    slots_.push_back(std::move(slot));
  };
  for (const AgentConfig& a : agents_) attach(a, std::make_shared<const AgentPath>(a));
  for (const AgentConfig& a : reserved_) attach(a, nullptr);
}

void EffectsStage::AgentSlot::Follow(std::shared_ptr<const AgentPath> new_path) {
  path = std::move(new_path);
  const std::shared_ptr<const AgentPath> p = path;
  const Pose rest = parked;
  animator = std::make_shared<AgentAnimator>(kind, height_m,
                                             [p, rest](double t) { return p ? p->X_WA(t) : rest; });
}

void EffectsStage::Replace(std::vector<EffectConfig> effects, std::vector<AgentConfig> agents,
                           std::optional<AdversityPreset> preset,
                           std::unique_ptr<EffectsEngine> engine) {
  std::vector<std::shared_ptr<const AgentPath>> paths(slots_.size());
  for (const AgentConfig& a : agents) {
    const auto it = std::find(body_names_.begin(), body_names_.end(), a.name);
    if (it == body_names_.end())
      throw ConfigError("", 0, "npcs",
                        "agent '" + a.name +
                            "' has no body in this run (MuJoCo 2.2.2 cannot add bodies to a "
                            "loaded model); expected at most the NPCs the run started with");
    paths[it - body_names_.begin()] = std::make_shared<const AgentPath>(a);
  }
  for (size_t i = 0; i < slots_.size(); ++i) slots_[i]->Follow(paths[i]);
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
  return engine_->Evaluate(snapshot.time_sec, viewer_W, &snapshot.X_WB);
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
