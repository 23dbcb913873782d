#pragma once
// NPC agents: people and vehicles that walk or drive a waypoint path in the
// world. an agent is a kinematic (mocap) body in the composed MJCF
// (compose/agent_bodies.h), posed every physics step from AgentPath::X_WA(the episode's time)
// (physics Simulation::AddMocapDriver). coupling is one-way: robots and free bodies
// collide with agents and are pushed by them; agents follow their path whatever they touch.
//
// motion model (pure, deterministic, no randomness): the agent stands at waypoints[0] for
// start_delay_sec, then moves along straight legs between consecutive waypoints at the
// constant speed speed_m_s, stopping pause_sec at every waypoint it reaches. the agent
// faces along the leg it walks (yaw = atan2(dy, dx)); while paused it keeps the heading
// of the leg it arrived on, and it turns instantly when it sets off. routes:
//   loop      w0 -> w1 -> ... -> w(n-1) -> w0 -> ... (closed, repeats)
//   pingpong  w0 -> ... -> w(n-1) -> ... -> w0 -> ... (there and back, repeats)
//   once      w0 -> ... -> w(n-1), then stands at w(n-1) facing along the last leg
// frames: the agent frame A has its origin on the floor (z = floor_z) under the agent's
// centre, x forward (walking direction), y left, z up (REP-103).

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "penumbra/core/pose.h"

namespace penumbra {

/// what an agent looks like (its MJCF body, compose/agent_bodies.h) and its segmentation class.
enum class AgentKind {
  kPerson,    ///< "person": a 1.75 m (height_m) figure of capsules and boxes
  kForklift,  ///< "forklift": a counterbalance forklift of boxes, about 2.75 x 1.1 x 2.1 m with
              ///< forks
  kCart,      ///< "cart": a hand cart, 1.0 x 0.6 x 1.0 m
};

/// how an agent continues after its last waypoint (see the file header).
enum class AgentRoute { kLoop, kPingPong, kOnce };

/// how an agent moves: `scripted` follows its waypoints in straight legs as a pure function of
/// time (this file); `crowd` plans on the walkable region of its kind and avoids the others
/// and the robots (effects/crowd_sim.h).
enum class AgentMotion { kScripted, kCrowd };

/// what a crowd agent does about the robots (effects/crowd_sim.h): `avoid` keeps clearance_m
/// from them, `ignore` walks as if they were not there, `block` steps into a robot's path.
enum class AgentBehaviour { kAvoid, kIgnore, kBlock };

/// a crowd agent's goals: `patrol` visits its waypoints in route order, `random` walks to a
/// waypoint (point of interest) drawn from the world seed each time it reached one.
enum class AgentGoals { kPatrol, kRandom };

/// semantic-segmentation class ids of agent geoms (Geom::semantic_class). the ids are the
/// Cityscapes label ids (Cordts et al., "The Cityscapes Dataset for Semantic Urban Scene
/// Understanding", CVPR 2016): 24 = person, 27 = truck (used for every vehicle agent).
inline constexpr int kSemanticClassPerson = 24;
inline constexpr int kSemanticClassVehicle = 27;

/// world-file name of a kind ("person", "forklift", "cart") and of a route.
const char* AgentKindName(AgentKind kind);
const char* AgentRouteName(AgentRoute route);
/// world-file names of motions ("scripted", "crowd"), behaviours ("avoid", "ignore",
/// "block") and goals ("patrol", "random").
const char* AgentMotionName(AgentMotion motion);
const char* AgentBehaviourName(AgentBehaviour behaviour);
const char* AgentGoalsName(AgentGoals goals);
/// semantic class of every geom of an agent of `kind`.
int AgentSemanticClass(AgentKind kind);

/// one entry of the world file's `agents:` list.
struct AgentConfig {
  std::string name;  ///< [A-Za-z0-9_-]+, unique among agents
  AgentKind kind = AgentKind::kPerson;
  std::vector<Eigen::Vector2d> waypoints;  ///< >= 2 floor points (x, y) in the world, m
  double speed_m_s = 1.3;                  ///< (0, 20]; 1.3 m/s is a typical walking speed
  double pause_sec = 0;                    ///< [0, 3600], idle time at every waypoint reached
  double start_delay_sec = 0;              ///< [0, 3600], idle at waypoints[0] first
  AgentRoute route = AgentRoute::kLoop;
  double floor_z = 0;      ///< height of the floor it walks on, m, finite
  double height_m = 1.75;  ///< person: body height, [0.5, 2.5] m (others ignore it)
  /// person: height_m was given (world file `height_m`); otherwise the body's height is drawn
  /// from the world seed (effects/walker_gait.h WalkerAppearanceOf) and height_m is unused
  bool height_given = false;
  AgentMotion motion = AgentMotion::kScripted;
  AgentBehaviour behaviour = AgentBehaviour::kAvoid;  ///< crowd motion only
  AgentGoals goals = AgentGoals::kPatrol;             ///< crowd motion only
  double clearance_m = 0.5;  ///< avoid: kept from a robot's disc, [0, 10] m (crowd only)
  /// crowd only: false (the default) = the agent never moves into a robot's disc and, when a
  /// robot comes into its own, steps away (yields; a `block` agent holds still instead), so an
  /// agent never pins or knocks a robot; true = no such rule (an `ignore` agent walks through
  /// a robot, a vehicle brakes at its own rate), what a world asks for with `contact: true`
  /// and a preset with npcs.contact (effects/crowd_sim.h "contact")
  bool robot_contact = false;
  int line = 0;  ///< line of the entry in the world file (0 = unknown)

  /// checks names, ranges and the path (>= 2 waypoints, consecutive waypoints >= 1 cm
  /// apart, every value finite).
  /// @param file       file named in the error ("" = command line / generated)
  /// @param key_prefix key path of this entry, e.g. "agents[2]"
  /// @param line_of    optional: 1-based line of a key path (0 = unknown; then `line`)
  /// @throws ConfigError(file, line, "<key_prefix>.<key>", "<problem>; expected <range>").
  void ValidateOrThrow(const std::string& file, const std::string& key_prefix,
                       const std::function<int(const std::string&)>& line_of = {}) const;
};

/// validates every agent (keys "agents[i].<key>") and that names are unique.
/// @throws ConfigError as AgentConfig::ValidateOrThrow.
void ValidateAgentsOrThrow(const std::vector<AgentConfig>& agents, const std::string& file);

/// the pose of an agent over sim time. construct from a validated AgentConfig.
class AgentPath {
 public:
  /// @throws ConfigError if `config` is invalid (as AgentConfig::ValidateOrThrow with key
  ///         prefix "agents['<name>']").
  explicit AgentPath(const AgentConfig& config);

  /// X_WA: pose of the agent frame in the world at sim time t (s); t < 0 counts as 0.
  Pose X_WA(double time_sec) const;
  /// position of the agent frame origin (on the floor) at t, m.
  Eigen::Vector3d Position(double time_sec) const;
  /// heading (yaw about +z from +x, rad) at t.
  double Yaw(double time_sec) const;
  /// length of one route cycle after the start delay, s (once: the time to the last
  /// waypoint including its pauses).
  double cycle_sec() const { return cycle_sec_; }
  const AgentConfig& config() const { return config_; }

 private:
  struct Leg {
    Eigen::Vector2d from, to;
    double t_start = 0;   // leaves `from`, relative to the end of the start delay
    double t_arrive = 0;  // reaches `to`
    double t_end = 0;     // leaves `to` (after the pause)
    double yaw = 0;
  };
  // the leg active at time u after the start delay (u >= 0), within one cycle
  const Leg& LegAt(double u, double* local) const;

  AgentConfig config_;
  std::vector<Leg> legs_;
  double cycle_sec_ = 0;
};

}  // namespace penumbra
