#pragma once
// the crowd model of NPC agents with `motion: crowd` (docs/npcs.md): goals, A* plans
// on the walkable region of the agent's kind (effects/walkable_grid.h), reciprocal collision
// avoidance among agents and against the robots (ORCA, effects/orca.h), and a kinematic bicycle
// model for vehicles that follow lanes. the model is separate from physics: it steps at a fixed
// dt and reads only the robots' discs (position, velocity, heading), so it runs without
// rendering or MuJoCo (tests, `penumbra npc-map`) and, in a run, from the agents' mocap drivers
// (session/effects_stage.h).
//
// per step (every agent in index order; sums in a fixed order; no unordered containers):
//   goals     patrol: the waypoints in route order (loop, pingpong, once); random: a waypoint
//             (point of interest) other than the last, drawn from the agent's stream keyed by
//             the seed; block: the point 0.5 m ahead of the nearest robot's disc (plus the
//             agent's) along its heading, replanned every second. on reaching a goal
//             (within 0.2 m; vehicles 0.6 m) the agent pauses
//             pause_sec. each new goal and plan is a CrowdDecision.
//   plan      WalkableGrid::Plan from the agent to its goal on its kind's region; an `avoid`
//             agent's plan keeps out of the robots' discs plus its clearance. an agent that
//             has a plan but moved slower than 0.1 m/s for 4 s (a jam, a robot in a door)
//             gives up its goal and takes the next ("stuck").
//   preferred towards the next point of the plan at speed_m_s, slowing to stop at the goal.
//   people    ORCA (tau 2 s): other agents as discs (responsibility 1/2 between people, 1
//             against vehicles, which keep to their lanes); robots: avoid -> disc radius
//             robot + agent + clearance_m, block -> robot + agent, ignore -> not at all
//             (responsibility 1: robots are not assumed to avoid). heading turns towards the
//             velocity at <= 6 rad/s.
//   vehicles  the kinematic bicycle model (rear-axle reference point, wheelbase L): position
//             moves at speed v along the heading, heading rate v tan(delta) / L, steering
//             |delta| <= atan(L / turning_radius); delta from pure pursuit of the plan
//             (look-ahead 1.5 m; Coulter, "Implementation of the Pure Pursuit Path Tracking
//             Algorithm", CMU-RI-TR-92-01, 1992). speed: the largest v <= speed_m_s whose
//             velocity along the heading satisfies the ORCA half-planes of the others and the
//             robots (responsibility 1), else 0 (it stops; but speed_m_s when only the lower
//             bounds conflict: inside a neighbour's horizon, heading away). a pingpong lane is
//             driven back in
//             reverse (forklifts do), steering as a rear-steered bicycle.
//   walkable  a centre may only move to a walkable point of its kind's region and never deeper
//             into another agent's disc (agents already moved this step where they are now):
//             the step is taken whole, else along x or y alone, else half, else not at all
//             (a vehicle: whole or not at all).
//   contact   an agent without robot_contact (the default; effects/agent_path.h) never moves
//             deeper into a robot's contact disc (robot radius + the agent's reach, the disc
//             that holds its whole body: a forklift's forks too, + 0.02 m), whatever its
//             behaviour, and ORCA keeps a vehicle's reach (not its disc) from the robots. when
//             a robot comes into an avoid or ignore agent's contact disc the agent yields: a
//             person walks straight away from the robot at its speed, a vehicle drives along
//             its axis away from it at up to 0.5 m/s (a "yield" decision; a `block` agent holds
//             still instead: the robot walked into it). so an agent never pins or knocks a
//             robot; with robot_contact (a preset's npcs.contact: true) none of this applies.
//             before that, a person (avoid or ignore, without robot_contact) standing where a
//             moving robot goes within 4 s (its swept corridor: its contact disc + 0.3 m
//             either side of its velocity) walks out of its way: to the nearest walkable point
//             beside or behind every moving robot's path and off every contact disc (+ 0.3 m)
//             (rings of 16 points 0.5-4 m away, the first 12 tried by A* round the robots'
//             contact discs; a "give_way" decision; none found: it looks again after 1 s),
//             then goes on.

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "penumbra/core/rng.h"
#include "penumbra/effects/agent_path.h"
#include "penumbra/effects/orca.h"
#include "penumbra/effects/walkable_grid.h"

namespace penumbra {

/// disc radius (plan view, ORCA and overlap), walkable profile and wheelbase of a kind.
struct AgentKindModel {
  double disc_radius_m = 0.25;  ///< the agent's body as a disc about its origin, m
  WalkableProfile walkable;     ///< what its walkable region is built from
  double wheelbase_m = 0;       ///< vehicles: L of the bicycle model (0 for people)
  /// the disc about the origin that holds the whole body (a forklift's fork tips, a walker's
  /// swinging arms), m: what is kept from a robot (see the file header's "contact")
  double reach_m = 0.3;
};

/// person: disc 0.25 m, reach 0.3 m, walkable radius 0.3 m, steps 0.1 m (a 0.144 m pallet is an
/// obstacle), passes under 2.0 m. forklift: disc 1.2 m (its chassis and counterweight about the
/// origin, not the fork tips; reach 1.95 m with the forks, compose/agent_bodies.cc), walkable
/// radius 0.7 m (half width + 0.15 m: it drives along lanes), steps 0.05 m, passes under 2.3 m,
/// turning radius 2.0 m. cart: disc 0.6 m, reach 0.6 m, walkable 0.45 m, turning radius 0.8 m.
/// wheelbase: the body's axle spacing, AgentWheelbase (effects/agent_animation.h): forklift
/// 1.1 m, cart 0.8 m.
AgentKindModel KindModel(AgentKind kind);
/// true for the kinds driven by the bicycle model (forklift, cart).
bool IsVehicle(AgentKind kind);

/// where a world's crowds go: its rooms or zones and its lanes (walkways, aisles, trails), in
/// the world frame, and which of them vehicles may drive. generated environments provide them
/// (environment/environment_generator.h GeneratedEnvironment::rooms, walkways and drivable;
/// environment/model_sources.h): a warehouse's zones and aisle are drivable, a house's rooms
/// and hallway are not.
struct CrowdSites {
  struct Area {
    std::string name;
    Eigen::Vector2d min_W{0, 0}, max_W{0, 0};  ///< plan bounding box, m
    bool drivable = false;                     ///< vehicles may drive here
  };
  struct Lane {
    std::string name;
    std::vector<Eigen::Vector2d> points_W;  ///< polyline, m
    bool drivable = false;                  ///< vehicles may drive along it
  };
  std::vector<Area> areas;
  std::vector<Lane> lanes;
  bool empty() const { return areas.empty() && lanes.empty(); }
  /// true when some area or lane is drivable.
  bool any_drivable() const;
  /// true when `p_W` lies in a drivable area's box or within `lane_half_width_m` of a drivable
  /// lane.
  bool Drivable(const Eigen::Vector2d& p_W, double lane_half_width_m = 1.0) const;
};

/// a robot as the crowd sees it: a disc in the plan.
struct CrowdRobot {
  Eigen::Vector2d position_W{0, 0};  ///< m
  Eigen::Vector2d velocity_W{0, 0};  ///< m/s
  double yaw = 0;                    ///< heading, rad
  double radius_m = 0.45;            ///< disc radius, m
};

/// one decision of the crowd (what a run log records as an "npc" event).
struct CrowdDecision {
  double time_sec = 0;
  int agent = 0;  ///< index into the agents
  ///< "goal", "block" (a new block point), "hold" (a `block` agent stands its ground in a
  ///< robot's path), "pause", "stuck", "blocked" (no plan to the goal), "give_way" (out of a
  ///< moving robot's way, to goal_W), "yield" (a robot
  ///< came into the agent's contact disc: it steps away; goal_W is the robot's position)
  std::string what;
  Eigen::Vector2d goal_W{0, 0};
  int plan_points = 0;  ///< points of the plan made (0 = none)
};

/// the state of one crowd agent.
struct CrowdAgentState {
  Eigen::Vector2d position_W{0, 0};  ///< agent frame origin (plan), m
  Eigen::Vector2d velocity_W{0, 0};  ///< m/s
  double yaw = 0;                    ///< heading, rad
};

/// the crowd: agents of `motion: crowd`, stepped together.
class CrowdSim {
 public:
  /// @param agents    the crowd's agents (validated AgentConfigs; their waypoints are patrol
  ///                  points, points of interest or a vehicle's lane; the agent starts at the
  ///                  walkable point nearest waypoints[0])
  /// @param person_region, vehicle_region  walkable regions (shared, not null) of people and
  ///                  of vehicles (forklift and cart share the vehicle region)
  /// @param seed      world seed (random goals)
  /// @param dt        step, s (> 0)
  /// @throws Error for a null region or dt <= 0.
  CrowdSim(std::vector<AgentConfig> agents, std::shared_ptr<const WalkableGrid> person_region,
           std::shared_ptr<const WalkableGrid> vehicle_region, uint64_t seed, double dt = 0.05);

  /// advances one step with the robots where they are now.
  void Step(const std::vector<CrowdRobot>& robots);

  double time_sec() const { return time_; }
  double dt() const { return dt_; }
  const std::vector<AgentConfig>& agents() const { return agents_; }
  const std::vector<CrowdAgentState>& states() const { return states_; }
  /// the region agent i walks on.
  const WalkableGrid& region(size_t i) const;
  /// takes agent i out of the crowd (a live change removed it) or back in: an inactive agent
  /// neither moves nor is avoided.
  void SetActive(size_t i, bool active);
  bool active(size_t i) const { return active_[i] != 0; }
  /// decisions made since the last call, in order; clears them.
  std::vector<CrowdDecision> TakeDecisions();

 private:
  struct Plan {
    std::vector<Eigen::Vector2d> points;
    size_t next = 0;  // index of the point headed for
    Eigen::Vector2d goal{0, 0};
    bool active = false;
  };
  void ChooseGoal(size_t i, const std::vector<CrowdRobot>& robots);
  void MakePlan(size_t i, const Eigen::Vector2d& goal, const char* what,
                const std::vector<CrowdRobot>& robots);
  /// records a decision of agent i at the current time (TakeDecisions).
  void Decide(size_t i, const char* what, const Eigen::Vector2d& goal_W, int plan_points = 0);
  Eigen::Vector2d Preferred(size_t i);
  void AddRobotLines(size_t i, const std::vector<CrowdRobot>& robots, double own_radius,
                     const Eigen::Vector2d& v_a, std::vector<OrcaLine>* lines) const;
  /// the robot nearest agent i (robots not empty).
  const CrowdRobot& NearestRobot(size_t i, const std::vector<CrowdRobot>& robots) const;
  /// whether `block` agent i stands in the nearest robot's path: ahead of it, inside its swept
  /// corridor (robot radius + agent radius either side of its heading), no farther than its
  /// block point plus kBlockHoldM.
  bool InRobotsPath(size_t i, const std::vector<CrowdRobot>& robots) const;
  /// the robot whose contact disc (robot radius + agent i's reach) agent i's centre at `p` is
  /// inside, deepest first; null when none or when agent i has robot_contact.
  const CrowdRobot* Touching(size_t i, const Eigen::Vector2d& p,
                             const std::vector<CrowdRobot>& robots) const;
  /// true when moving agent i's centre from `from` to `to` goes deeper into a robot's contact
  /// disc (never for robot_contact agents).
  bool EntersRobot(size_t i, const Eigen::Vector2d& from, const Eigen::Vector2d& to,
                   const std::vector<CrowdRobot>& robots) const;
  /// true when agent i's centre at `p` lies where a moving robot goes within 4 s: in
  /// its swept corridor (its contact disc + kGiveWayMarginM either side of its velocity),
  /// from its contact disc behind it to its contact disc ahead of where it will be.
  bool InRobotsWay(size_t i, const Eigen::Vector2d& p, const CrowdRobot& robot) const;
  /// plans agent i to the nearest walkable point out of every robot's way (a "give_way"
  /// decision); false when none is found.
  bool GiveWay(size_t i, const std::vector<CrowdRobot>& robots);

  std::vector<AgentConfig> agents_;
  std::shared_ptr<const WalkableGrid> person_region_, vehicle_region_;
  double dt_;
  double time_ = 0;
  std::vector<CrowdAgentState> states_;
  std::vector<Plan> plans_;
  std::vector<Rng> rngs_;
  std::vector<int> goal_index_;  // patrol: the waypoint headed for; random: the last drawn
  std::vector<int> patrol_dir_;  // pingpong: +1 / -1
  std::vector<double> pause_until_;
  std::vector<double> replan_at_;   // block: the time of the next replan
  std::vector<uint8_t> holding_;    // block: standing its ground in a robot's path
  std::vector<int> gear_;           // vehicles: +1 forward, -1 reverse
  std::vector<double> speed_;       // vehicles: signed speed along the heading, m/s
  std::vector<double> slow_since_;  // start of the agent's current spell below 0.1 m/s
  std::vector<uint8_t> active_;
  std::vector<uint8_t> yielding_;       // stepping away from a robot that came into it
  std::vector<uint8_t> giving_way_;     // walking out of a moving robot's way
  std::vector<double> give_way_retry_;  // no refuge found: the time of the next look
  std::vector<CrowdDecision> decisions_;
};

}  // namespace penumbra
