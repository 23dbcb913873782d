#pragma once
// the adverse-condition stage of a run: the world's `effects:`, its NPC
// `agents:` and an adversity preset (world key `adversity`, or --adversity) put together.
//
// order in a run (run/runner.cc):
//   1. compose the models, then EffectsStage(world, &composed, ...) plans the preset
//      (regions and NPC paths need the scene: with a preset it compiles the composed
//      document once more to read the static geometry) and adds the mocap bodies of every
//      agent (root and parts: limbs, wheels; compose/agent_bodies.h) to `composed`;
//   2. load the simulation, Attach(&sim): the world's agents are checked against the
//      world's extent, then every agent's root body is driven from its path and its part
//      bodies from the root's motion (effects/agent_animation.h);
//   3. Bind(scene): labels agent geoms (Geom::semantic_class, effects/agent_path.h) and
//      builds the EffectsEngine on the final scene;
//   4. per rendered frame, after physics: Evaluate(snapshot, camera position) -> the
//      EffectsFrame that camera sees, passed beside the (immutable) snapshot to
//      Renderer::Render. effects never feed back into physics.
//
// how a preset (world/adversity_preset.h) is placed in a world:
//   floor      the highest static upward-facing plane at or below the lowest robot's root
//              pose (else that pose's z; 0 without robots)
//   area       the bounding box of the free floor (0.1 m cells, 0.4 m clearance from static
//              geometry between 0.05 and 2 m above the floor) reachable from the first
//              robot, within the static geometry's plan-view box joined with +-5 m around the
//              robots' mean start, clipped to +-15 m (FloorMap): a room's interior, or +-5 m
//              in the open
//   fog, dust  everywhere (no region); fog base height = floor + 1 m for height falloff
//   smoke      noise smoke in a box centred on the area, extent_fraction of its size,
//              from the floor to floor + height_m, drifting at 0.3 m/s along +x
//   rain, snow around the viewer (effect defaults), at the preset rate
//   lights     a `blackout` light event on "*" at min_scale = lights.scale for the whole
//              run, plus a `flicker` event when flicker_depth > 0
//   npcs       crowd agents (effects/crowd_sim.h; docs/npcs.md) on the walkable map
//              (session/npc_map.h) seeded at the robots' starts. points of interest: the
//              walkable points nearest the world's area centres and lane points (CrowdSites,
//              from a generated environment's rooms and walkways), else 6 walkable points
//              drawn from the seed. person i: odd i patrol a lane there and back when
//              one is walkable, else random goals among the points of interest; it starts
//              at one >= 1.5 m from every robot start. with behaviour `block` every
//              person (no lane patrols) starts in front of robot i mod robots instead: a
//              walkable cell 2-6 m from its start within 60 deg of its start heading, else
//              1.5-8 m in its forward half-space, >= 1.5 m from every robot start (drawn
//              from the seed; a point of interest when none is free, logged). with the
//              preset's npcs.block_goal (the robots' goal) a blocker starts near the robot's
//              route to it instead: the A* path on the people's walkable cells (else the
//              straight segment), at an arc length drawn in [min(2, L), min(6, L)] m (L the
//              route's length), up to 1 m to its side; failing that, by the heading rule. vehicles
//              (forklifts at 1.5x speed) drive a drivable lane (its longest stretch they fit,
//              >= 3 m) there and back; without one, a straight lane of 3-12 m drawn from the
//              seed inside the world's drivable areas. vehicles go only where the world says
//              they may drive (CrowdSites' drivable areas and lanes: a generated warehouse's
//              zones and aisle; never a house, a hand-built room or the outdoor terrain): a
//              world without a drivable area gets none (one log line), nor one whose drivable
//              lanes and areas no forklift fits (logged). behaviour, clearance and contact
//              (AgentConfig::robot_contact: whether they may push a robot) from the preset.
// preset effects and agents are named "adversity_<what>" and follow the world's own.

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "penumbra/compose/mocap_body_spec.h"
#include "penumbra/compose/scene_composer.h"
#include "penumbra/effects/agent_animation.h"
#include "penumbra/effects/agent_path.h"
#include "penumbra/effects/crowd_sim.h"
#include "penumbra/effects/effect_config.h"
#include "penumbra/effects/effects_engine.h"
#include "penumbra/scene/effects_frame.h"
#include "penumbra/scene/scene_description.h"
#include "penumbra/scene/world_snapshot.h"
#include "penumbra/session/crowd_runner.h"
#include "penumbra/session/npc_map.h"
#include "penumbra/world/adversity_preset.h"
#include "penumbra/world/world_config.h"

namespace penumbra {

class Simulation;

/// the effects, agents and preset of one run.
class EffectsStage {
 public:
  /// plans the run's effects and agents and adds the agents' bodies to `composed`.
  /// @param adversity_override a preset spec from the command line (--adversity), or ""
  ///        for the world's own `adversity` key
  /// @param reserve_live_npcs also add parked bodies for the NPCs the bundled presets can ask
  ///        for (LiveNpcReserve), so that a live change to a bundled preset can bring them in
  ///        (live/live_effects.h; bodies are not added to a loaded model)
  /// @throws ConfigError for an unknown preset, invalid agents or invalid effects.
  /// @param sites the world's areas and lanes for placing crowds (CrowdSites; empty = none)
  EffectsStage(const WorldConfig& world, ComposedScene* composed,
               const std::string& adversity_override = "", bool reserve_live_npcs = false,
               CrowdSites sites = {});
  ~EffectsStage();

  /// checks the world's agents against `sim`'s static geometry, then drives every agent's
  /// mocap body from its path (Simulation::AddMocapDriver). `sim` is the composed model
  /// loaded, before its first step; this stage outlives its stepping. agents follow the
  /// episode's time (the drivers' t): at a new episode (Simulation::ResetControllers, as
  /// `reset` and a kinematic replay of a run with resets call it) every agent starts again
  /// as at the run's start: paths from their time 0, fresh animators, the crowd as just
  /// constructed (the same seed, the same walkable map), so two episodes of the same actions
  /// move the agents alike. the restart happens at the drivers' next call.
  /// @throws ConfigError for a waypoint of a world agent outside the world (the static
  ///         geometry's plan-view box + 1 m), naming agents[i].waypoints[j].
  void Attach(Simulation* sim);

  /// `scene` with every agent geom that has no class yet (a world-file `semantic_classes`
  /// entry wins) labelled with its agent class (effects/agent_path.h); builds the effects
  /// engine on it. call once, before Evaluate.
  /// @throws ConfigError from the EffectsEngine (unknown light or body names, bad .vdb).
  SceneDescription Bind(SceneDescription scene);

  /// the effects at the snapshot's episode time (SimTimeOfStep(step - episode_start_step):
  /// the run's time in the first episode, from 0 again after each `reset`) for a viewer at
  /// viewer_W; null when the run has no effects (clear conditions). deterministic.
  std::shared_ptr<const EffectsFrame> Evaluate(const WorldSnapshot& snapshot,
                                               const Eigen::Vector3d& viewer_W);

  /// a live change (live/live_effects.h): the run's effects, agents and preset become
  /// these from now on; `engine` is the EffectsEngine bound to them (null when `effects` is
  /// empty). each agent body attached (Attach) follows the path of the agent of the same name
  /// in `agents`, or is parked when it has none (AgentParkedPose); the bodies' poses change
  /// at the driver's next call (Simulation::ApplyMocapDrivers or the next step). call on the
  /// loop thread at a step boundary (Evaluate and the mocap drivers run there).
  /// @throws ConfigError("", 0, "npcs", ...) naming an agent without a body, before anything
  ///         changes (bodies are not added to a loaded model).
  void Replace(std::vector<EffectConfig> effects, std::vector<AgentConfig> agents,
               std::optional<AdversityPreset> preset, std::unique_ptr<EffectsEngine> engine);
  /// names of the agents whose bodies the model has (the agents at Attach), in order.
  const std::vector<std::string>& agent_bodies() const { return body_names_; }
  /// the walkable map of the crowd (null when no agent has `motion: crowd`), its sites, and
  /// the running crowd (null likewise).
  std::shared_ptr<const NpcMap> npc_map() const { return npc_map_; }
  const CrowdSites& sites() const { return sites_; }
  std::shared_ptr<const CrowdRunner> crowd() const { return crowd_; }
  /// every crowd decision from now on goes to `sink` (sim time, JSON payload; run/runner.cc
  /// records them as "npc" events of the run log). called from the physics thread.
  void set_crowd_decision_sink(std::function<void(double, const std::string&)> sink);
  /// the world seed (keys the effects' random streams).
  uint64_t seed() const { return seed_; }

  /// all effects (the world's, then the preset's) and all agents.
  const std::vector<EffectConfig>& effects() const { return effects_; }
  const std::vector<AgentConfig>& agents() const { return agents_; }
  /// the preset applied, if any (`none` counts as applied).
  const std::optional<AdversityPreset>& preset() const { return preset_; }

  /// run.json entries: "name: type" per effect, "name: kind" per agent, preset "name (file)".
  /// thread-safe against Replace (a live recording's header reads the preset label).
  std::vector<std::string> EffectLabels() const;
  std::vector<std::string> AgentLabels() const;
  std::string PresetLabel() const;

 private:
  mutable std::mutex mu_;  // guards effects_, agents_, preset_ between Replace and the labels
  std::vector<EffectConfig> effects_;
  std::vector<AgentConfig> agents_;
  std::optional<AdversityPreset> preset_;
  uint64_t seed_ = 0;
  std::string world_file_;
  size_t world_agents_ = 0;  // agents_[0, world_agents_) are the world's, then the preset's
  std::vector<Eigen::Vector3d> robot_starts_;
  std::vector<double> robot_yaws_;
  std::unique_ptr<EffectsEngine> engine_;
  // the path each attached agent body follows (null = parked), shared with its mocap driver;
  // crowd agents follow the crowd instead
  struct AgentSlot {
    std::shared_ptr<const AgentPath> path;
    std::shared_ptr<CrowdRunner> crowd;
    size_t crowd_index = 0;
    Pose parked;
    AgentKind kind = AgentKind::kPerson;
    double height_m = 1.75;
    std::shared_ptr<AgentAnimator> animator;  // poses the root and parts from path (or parked)
    // follows `new_path` (null: parked) from now on, with a fresh animator
    void Follow(std::shared_ptr<const AgentPath> new_path);
  };
  // a crowd runner for the crowd agents of `agents` (null if none), with its time 0 at
  // start_sec (episode time); sets npc_map_ (`map` when given, else built)
  std::shared_ptr<CrowdRunner> MakeCrowd(const std::vector<AgentConfig>& agents, double start_sec,
                                         std::shared_ptr<const NpcMap> map = nullptr);
  // restarts every agent when the simulation's episode start moved (Attach); physics thread
  void FollowEpisode();
  // decision_sink_ at sim time for a crowd on the episode's time
  std::function<void(double, const std::string&)> EpisodeDecisionSink();
  int64_t episode_start_ = 0;       // the episode start step the agents follow
  double episode_start_sec_ = 0.0;  // its sim time
  CrowdSites sites_;
  std::vector<ModelConfig> robots_;
  Simulation* sim_ = nullptr;
  std::shared_ptr<const NpcMap> npc_map_;
  std::shared_ptr<CrowdRunner> crowd_;
  std::function<void(double, const std::string&)> decision_sink_;
  std::vector<std::string> body_names_;
  std::vector<std::shared_ptr<AgentSlot>> slots_;
  // parked NPC bodies without an agent at the start (reserve_live_npcs)
  std::vector<AgentConfig> reserved_;
};

/// the NPC bodies a live run reserves: the most people and vehicles any bundled adversity
/// preset (worlds/adversity/presets.yaml: minor, major) asks for.
/// @throws ConfigError when the bundled presets cannot be read.
std::pair<int, int> LiveNpcReserve();

/// where an agent body without an agent waits (a live change removed its NPC): at its path's
/// start, 100 m below the agent's floor, out of every camera's and sensor's view above the
/// floor.
Pose AgentParkedPose(const AgentConfig& agent);

/// the start heading of each robot of `world` (in the order of its models): the yaw (rad
/// about +z, 0 = +x) of its pose's x axis projected on the floor.
std::vector<double> RobotStartYaws(const WorldConfig& world);

/// the preset's effects and agents for a world whose scene at the start is (scene, X_WB),
/// as described in the file header. pure and deterministic in (preset, world, seed).
/// @param robot_starts start positions (world xy) of the robots' root bodies
/// @param robot_yaws   their start headings (rad about +z, 0 = +x; RobotStartYaws), in the
///                     same order; a missing one counts as 0. `block` people start in front
///                     of a robot (the header's "npcs")
/// @param sites        the world's areas and lanes (empty: points drawn from the seed)
void PlanAdversityPreset(const AdversityPreset& preset, const SceneDescription& scene,
                         const std::vector<Pose>& X_WB,
                         const std::vector<Eigen::Vector3d>& robot_starts,
                         const std::vector<double>& robot_yaws, uint64_t seed,
                         std::vector<EffectConfig>* effects, std::vector<AgentConfig>* agents,
                         const CrowdSites& sites = {});

/// true when `agent` may touch a robot: a scripted agent follows its path whatever it
/// touches, a crowd agent with robot_contact may push, a `block` one stands in the robot's way
/// (effects/crowd_sim.h "contact"); other crowd agents keep clear of robots and yield.
bool AgentMayTouchRobot(const AgentConfig& agent);

/// the agents of `agents` that may touch a robot (AgentMayTouchRobot) and whose root body is
/// not one of `mocap_bodies` (e.g. the mocap bodies a run log holds), in order: agents a
/// kinematic replay would add, moving on their own while the robot moves as logged, which
/// cannot show the contact.
std::vector<AgentConfig> TouchingAgentsWithout(const std::vector<AgentConfig>& agents,
                                               const std::vector<std::string>& mocap_bodies);

/// what agent `agent` looks like in a run of world seed `seed`: WalkerAppearanceOf(seed, its
/// name, its height_m when height_given, else 0: drawn from the seed).
WalkerAppearance AgentAppearance(const AgentConfig& agent, uint64_t seed);

/// the mocap body of each agent for compose/agent_bodies.h, in the same order: name, shape of
/// its kind, height and colours (AgentAppearance) and its path's pose at t = 0
/// (AgentPath::X_WA(0)).
/// @throws ConfigError if an agent is invalid (as AgentPath's constructor).
std::vector<MocapBodySpec> AgentBodySpecs(const std::vector<AgentConfig>& agents, uint64_t seed);

}  // namespace penumbra
