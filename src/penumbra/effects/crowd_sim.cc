#include "penumbra/effects/crowd_sim.h"

#include <algorithm>
#include <cmath>

#include "penumbra/core/error.h"
#include "penumbra/effects/agent_animation.h"

namespace penumbra {
namespace {

// key of the crowd's random goal draws (core/rng.h streams)
constexpr uint64_t kCrowdStream = 0xC20D5E1D0ULL;
constexpr double kTau = 2.0;                // ORCA time horizon, s
constexpr double kNeighbourM = 8.0;         // neighbours farther than this are not considered, m
constexpr double kReachedM = 0.2;           // a goal within this is reached (people), m
constexpr double kVehicleReachedM = 0.6;    // ... by a vehicle (its turns are limited), m
constexpr double kWaypointM = 0.3;          // a plan point within this is passed, m
constexpr double kTurnRate = 6.0;           // people's heading rate limit, rad/s
constexpr double kLookAheadM = 1.5;         // pure pursuit look-ahead, m
constexpr double kVehicleAccel = 1.5;       // vehicles' speed change limit, m/s^2
constexpr double kSafetyM = 0.02;           // added to every combined radius, m
constexpr double kBlockReplanSec = 1.0;     // a `block` agent's new block point, s
constexpr double kBlockAheadM = 0.5;        // block point: this far beyond the discs' contact, m
constexpr double kBlockHoldM = 0.5;         // holds while no farther than the block point + this, m
constexpr double kVehicleYieldSpeed = 0.5;  // a vehicle backs away from a robot at most this, m/s
constexpr double kGiveWaySec = 4.0;  // a person keeps out of where a robot goes this far ahead, s
constexpr double kGiveWayMarginM = 0.3;  // ... and this much beside its contact disc, m

// the direction a robot is going: its velocity when moving, else its yaw
Eigen::Vector2d RobotHeading(const CrowdRobot& robot) {
  return robot.velocity_W.norm() > 0.1 ? Eigen::Vector2d(robot.velocity_W.normalized())
                                       : Eigen::Vector2d(std::cos(robot.yaw), std::sin(robot.yaw));
}

double WrapAngle(double a) { return std::remainder(a, 2 * M_PI); }

}  // namespace

AgentKindModel KindModel(AgentKind kind) {
  AgentKindModel m;
  switch (kind) {
    case AgentKind::kPerson:
      m.disc_radius_m = 0.25;
      m.reach_m = 0.3;
      m.walkable = {0.3, 0.1, 2.0, 0.0};
      break;
    case AgentKind::kForklift:
      m.disc_radius_m = 1.2;
      m.reach_m = 1.95;  // fork tips at x = 1.9 m, y = +-0.3 m
      m.walkable = {0.7, 0.05, 2.3, 2.0};
      m.wheelbase_m = AgentWheelbase(kind);
      break;
    case AgentKind::kCart:
      m.disc_radius_m = 0.6;
      m.reach_m = 0.6;
      m.walkable = {0.45, 0.05, 1.2, 0.8};
      m.wheelbase_m = AgentWheelbase(kind);
      break;
  }
  return m;
}

bool IsVehicle(AgentKind kind) { return kind != AgentKind::kPerson; }

bool CrowdSites::any_drivable() const {
  return std::any_of(areas.begin(), areas.end(), [](const Area& a) { return a.drivable; }) ||
         std::any_of(lanes.begin(), lanes.end(), [](const Lane& l) { return l.drivable; });
}

bool CrowdSites::Drivable(const Eigen::Vector2d& p_W, double lane_half_width_m) const {
  for (const Area& a : areas)
    if (a.drivable && (p_W.array() >= a.min_W.array()).all() &&
        (p_W.array() <= a.max_W.array()).all())
      return true;
  for (const Lane& l : lanes) {
    if (!l.drivable) continue;
    for (size_t k = 0; k + 1 < l.points_W.size(); ++k) {
      const Eigen::Vector2d d = l.points_W[k + 1] - l.points_W[k];
      const double t = d.squaredNorm() > 0
                           ? std::clamp((p_W - l.points_W[k]).dot(d) / d.squaredNorm(), 0.0, 1.0)
                           : 0.0;
      if ((p_W - (l.points_W[k] + t * d)).norm() <= lane_half_width_m) return true;
    }
  }
  return false;
}

CrowdSim::CrowdSim(std::vector<AgentConfig> agents,
                   std::shared_ptr<const WalkableGrid> person_region,
                   std::shared_ptr<const WalkableGrid> vehicle_region, uint64_t seed, double dt)
    : agents_(std::move(agents)),
      person_region_(std::move(person_region)),
      vehicle_region_(std::move(vehicle_region)),
      dt_(dt) {
  if (!person_region_ || !vehicle_region_) throw Error("CrowdSim: a walkable region is null");
  if (!(dt > 0) || !std::isfinite(dt)) throw Error("CrowdSim: dt must be > 0");
  const size_t n = agents_.size();
  states_.resize(n);
  plans_.resize(n);
  goal_index_.assign(n, 0);
  patrol_dir_.assign(n, 1);
  pause_until_.resize(n);
  replan_at_.assign(n, 0);
  holding_.assign(n, 0);
  gear_.assign(n, 1);
  speed_.assign(n, 0);
  slow_since_.assign(n, 0);
  active_.assign(n, 1);
  yielding_.assign(n, 0);
  giving_way_.assign(n, 0);
  give_way_retry_.assign(n, 0.0);
  for (size_t i = 0; i < n; ++i) {
    const AgentConfig& a = agents_[i];
    rngs_.emplace_back(HashKeys(seed, kCrowdStream, i));
    const Eigen::Vector2d start =
        region(i).NearestWalkable(a.waypoints[0]).value_or(a.waypoints[0]);
    states_[i].position_W = start;
    const Eigen::Vector2d d = a.waypoints[1] - a.waypoints[0];
    states_[i].yaw = std::atan2(d.y(), d.x());
    pause_until_[i] = a.start_delay_sec;
  }
}

const WalkableGrid& CrowdSim::region(size_t i) const {
  return IsVehicle(agents_[i].kind) ? *vehicle_region_ : *person_region_;
}

void CrowdSim::SetActive(size_t i, bool active) {
  active_.at(i) = active ? 1 : 0;
  if (!active) states_[i].velocity_W = Eigen::Vector2d::Zero();
}

std::vector<CrowdDecision> CrowdSim::TakeDecisions() {
  std::vector<CrowdDecision> out;
  out.swap(decisions_);
  return out;
}

void CrowdSim::MakePlan(size_t i, const Eigen::Vector2d& goal, const char* what,
                        const std::vector<CrowdRobot>& robots) {
  Plan& plan = plans_[i];
  std::vector<std::pair<Eigen::Vector2d, double>> keep_out;
  if (agents_[i].behaviour == AgentBehaviour::kAvoid)
    for (const CrowdRobot& r : robots)
      keep_out.emplace_back(r.position_W, r.radius_m + agents_[i].clearance_m +
                                              KindModel(agents_[i].kind).disc_radius_m);
  auto points = region(i).Plan(states_[i].position_W, goal, keep_out);
  slow_since_[i] = time_;
  if (!points) {
    plan.active = false;
    Decide(i, "blocked", goal);
    return;
  }
  plan.points = std::move(*points);
  plan.next = plan.points.size() > 1 ? 1 : 0;
  plan.goal = plan.points.back();
  plan.active = true;
  Decide(i, what, plan.goal, static_cast<int>(plan.points.size()));
}

void CrowdSim::Decide(size_t i, const char* what, const Eigen::Vector2d& goal_W, int plan_points) {
  CrowdDecision d;
  d.time_sec = time_;
  d.agent = static_cast<int>(i);
  d.what = what;
  d.goal_W = goal_W;
  d.plan_points = plan_points;
  decisions_.push_back(std::move(d));
}

void CrowdSim::ChooseGoal(size_t i, const std::vector<CrowdRobot>& robots) {
  const AgentConfig& a = agents_[i];
  const int n = static_cast<int>(a.waypoints.size());
  if (a.behaviour == AgentBehaviour::kBlock && !robots.empty()) {
    // the point kBlockAheadM beyond the discs' contact ahead of the nearest robot along its
    // heading
    const CrowdRobot& robot = NearestRobot(i, robots);
    const double ahead = robot.radius_m + KindModel(a.kind).disc_radius_m + kBlockAheadM;
    MakePlan(i, robot.position_W + ahead * RobotHeading(robot), "block", robots);
    replan_at_[i] = time_ + kBlockReplanSec;
    return;
  }
  int next = goal_index_[i];
  if (a.goals == AgentGoals::kRandom) {
    next = static_cast<int>(rngs_[i].NextU64() % static_cast<uint64_t>(n - 1));
    if (next >= goal_index_[i]) ++next;
  } else if (a.route == AgentRoute::kLoop) {
    next = (goal_index_[i] + 1) % n;
  } else if (a.route == AgentRoute::kPingPong) {
    if (goal_index_[i] + patrol_dir_[i] < 0 || goal_index_[i] + patrol_dir_[i] >= n)
      patrol_dir_[i] = -patrol_dir_[i];
    next = goal_index_[i] + patrol_dir_[i];
    if (IsVehicle(a.kind)) gear_[i] = patrol_dir_[i];
  } else {
    if (goal_index_[i] + 1 >= n) return;  // once: stays at the last waypoint
    next = goal_index_[i] + 1;
  }
  goal_index_[i] = next;
  MakePlan(i, a.waypoints[next], "goal", robots);
}

const CrowdRobot& CrowdSim::NearestRobot(size_t i, const std::vector<CrowdRobot>& robots) const {
  size_t best = 0;
  for (size_t r = 1; r < robots.size(); ++r)
    if ((robots[r].position_W - states_[i].position_W).squaredNorm() <
        (robots[best].position_W - states_[i].position_W).squaredNorm())
      best = r;
  return robots[best];
}

bool CrowdSim::InRobotsPath(size_t i, const std::vector<CrowdRobot>& robots) const {
  const CrowdRobot& robot = NearestRobot(i, robots);
  const Eigen::Vector2d h = RobotHeading(robot);
  const Eigen::Vector2d rel = states_[i].position_W - robot.position_W;
  const double own = KindModel(agents_[i].kind).disc_radius_m;
  const double along = rel.dot(h);
  const double lateral = std::abs(h.x() * rel.y() - h.y() * rel.x());
  return along > 0 && along <= robot.radius_m + own + kBlockAheadM + kBlockHoldM &&
         lateral <= robot.radius_m + own;
}

Eigen::Vector2d CrowdSim::Preferred(size_t i) {
  Plan& plan = plans_[i];
  if (!plan.active) return Eigen::Vector2d::Zero();
  const Eigen::Vector2d& p = states_[i].position_W;
  while (plan.next + 1 < plan.points.size() && (plan.points[plan.next] - p).norm() < kWaypointM)
    ++plan.next;
  const Eigen::Vector2d to = plan.points[plan.next] - p;
  const double dist = to.norm();
  if (dist < 1e-9) return Eigen::Vector2d::Zero();
  double speed = agents_[i].speed_m_s;
  if (plan.next + 1 == plan.points.size()) speed = std::min(speed, dist / dt_);
  return to / dist * speed;
}

const CrowdRobot* CrowdSim::Touching(size_t i, const Eigen::Vector2d& p,
                                     const std::vector<CrowdRobot>& robots) const {
  if (agents_[i].robot_contact) return nullptr;
  const double reach = KindModel(agents_[i].kind).reach_m + kSafetyM;
  const CrowdRobot* deepest = nullptr;
  double depth = 0;
  for (const CrowdRobot& r : robots) {
    const double d = r.radius_m + reach - (p - r.position_W).norm();
    if (d > depth) {
      depth = d;
      deepest = &r;
    }
  }
  return deepest;
}

bool CrowdSim::InRobotsWay(size_t i, const Eigen::Vector2d& p, const CrowdRobot& robot) const {
  const double speed = robot.velocity_W.norm();
  if (speed < 0.05) return false;
  const Eigen::Vector2d h = robot.velocity_W / speed;
  const Eigen::Vector2d rel = p - robot.position_W;
  const double contact = robot.radius_m + KindModel(agents_[i].kind).reach_m + kSafetyM;
  const double along = rel.dot(h);
  const double lateral = std::abs(h.x() * rel.y() - h.y() * rel.x());
  return along > -contact && along < speed * kGiveWaySec + contact &&
         lateral < contact + kGiveWayMarginM;
}

bool CrowdSim::GiveWay(size_t i, const std::vector<CrowdRobot>& robots) {
  const Eigen::Vector2d p = states_[i].position_W;
  const double reach = KindModel(agents_[i].kind).reach_m + kSafetyM;
  // beside or behind every moving robot's path (not further ahead on it, where the robot
  // still comes) and away from every robot's contact disc
  const auto clear = [&](const Eigen::Vector2d& q) {
    for (const CrowdRobot& r : robots) {
      const double contact = r.radius_m + reach;
      if ((q - r.position_W).norm() < contact + kGiveWayMarginM) return false;
      const double speed = r.velocity_W.norm();
      if (speed < 0.05) continue;
      const Eigen::Vector2d h = r.velocity_W / speed, rel = q - r.position_W;
      const double lateral = std::abs(h.x() * rel.y() - h.y() * rel.x());
      if (lateral < contact + kGiveWayMarginM && rel.dot(h) > -contact) return false;
    }
    return true;
  };
  // walkable points out of every robot's way, nearest first (rings of 16, a fixed order)
  std::vector<Eigen::Vector2d> refuges;
  for (const double d : {0.5, 0.8, 1.2, 1.6, 2.0, 2.5, 3.0, 4.0})
    for (int k = 0; k < 16; ++k) {
      const Eigen::Vector2d q =
          p + d * Eigen::Vector2d(std::cos(k * M_PI / 8), std::sin(k * M_PI / 8));
      if (region(i).Walkable(q) && clear(q)) refuges.push_back(q);
    }
  std::vector<std::pair<Eigen::Vector2d, double>> keep_out;
  for (const CrowdRobot& r : robots) keep_out.emplace_back(r.position_W, r.radius_m + reach);
  int tried = 0;
  for (const Eigen::Vector2d& q : refuges) {
    if (++tried > 12) break;
    const auto path = region(i).Plan(p, q, keep_out);
    if (!path || (path->back() - q).norm() > 0.2) continue;
    double length = 0;
    for (size_t k = 1; k < path->size(); ++k) length += ((*path)[k] - (*path)[k - 1]).norm();
    if (length > 2.5 * (q - p).norm() + 0.5) continue;
    Plan& plan = plans_[i];
    plan.points = *path;
    plan.next = plan.points.size() > 1 ? 1 : 0;
    plan.goal = plan.points.back();
    plan.active = true;
    slow_since_[i] = time_;
    Decide(i, "give_way", plan.goal, static_cast<int>(plan.points.size()));
    return true;
  }
  return false;
}

bool CrowdSim::EntersRobot(size_t i, const Eigen::Vector2d& from, const Eigen::Vector2d& to,
                           const std::vector<CrowdRobot>& robots) const {
  if (agents_[i].robot_contact) return false;
  const double reach = KindModel(agents_[i].kind).reach_m + kSafetyM;
  for (const CrowdRobot& r : robots) {
    const double d = (to - r.position_W).norm();
    if (d < r.radius_m + reach && d < (from - r.position_W).norm()) return true;
  }
  return false;
}

void CrowdSim::AddRobotLines(size_t i, const std::vector<CrowdRobot>& robots, double own_radius,
                             const Eigen::Vector2d& v_a, std::vector<OrcaLine>* lines) const {
  const AgentConfig& a = agents_[i];
  if (a.behaviour == AgentBehaviour::kIgnore) return;
  const double extra = a.behaviour == AgentBehaviour::kAvoid ? a.clearance_m : 0.0;
  // a vehicle keeps its whole body (its reach: the forks) from a robot, not its disc
  if (!a.robot_contact && IsVehicle(a.kind))
    own_radius = std::max(own_radius, KindModel(a.kind).reach_m);
  for (const CrowdRobot& r : robots) {
    const Eigen::Vector2d rel = r.position_W - states_[i].position_W;
    if (rel.norm() > kNeighbourM + extra) continue;
    lines->push_back(OrcaHalfPlane(v_a, rel, v_a - r.velocity_W,
                                   own_radius + r.radius_m + extra + kSafetyM, kTau, dt_, 1.0));
  }
}

void CrowdSim::Step(const std::vector<CrowdRobot>& robots) {
  const size_t n = agents_.size();
  // goals and preferred velocities
  std::vector<Eigen::Vector2d> preferred(n);
  for (size_t i = 0; i < n; ++i) {
    if (!active_[i]) continue;
    const AgentConfig& a = agents_[i];
    Plan& plan = plans_[i];
    if (a.behaviour == AgentBehaviour::kBlock && !robots.empty()) {
      // a blocker that reached its block point stands its ground while it stays in the robot's
      // path: it neither replans nor yields to the robot (a robot that keeps coming walks into
      // it); out of the path, it steps in front again
      const bool at_point = !plan.active || (states_[i].position_W - plan.goal).norm() < kReachedM;
      const bool hold =
          time_ >= pause_until_[i] && (holding_[i] || at_point) && InRobotsPath(i, robots);
      if (hold && !holding_[i]) {
        plan.active = false;
        Decide(i, "hold", states_[i].position_W);
      }
      holding_[i] = hold ? 1 : 0;
      if (!hold && time_ >= replan_at_[i] && time_ >= pause_until_[i]) ChooseGoal(i, robots);
    } else if (plan.active && (states_[i].position_W - plan.goal).norm() <
                                  (IsVehicle(a.kind) ? kVehicleReachedM : kReachedM)) {
      plan.active = false;
      pause_until_[i] = time_ + a.pause_sec;
      Decide(i, "pause", plan.goal);
    }
    if (plan.active && a.behaviour != AgentBehaviour::kBlock && time_ - slow_since_[i] > 4.0) {
      // stuck: give the goal up for the next
      Decide(i, "stuck", plan.goal);
      plan.active = false;
    }
    if (!plan.active && time_ >= pause_until_[i] && a.behaviour != AgentBehaviour::kBlock)
      ChooseGoal(i, robots);
    // a person in the way of a moving robot walks out of it first (it would else be cornered
    // where the robot goes: a door, a corner)
    if (!a.robot_contact && a.behaviour != AgentBehaviour::kBlock && !IsVehicle(a.kind)) {
      bool in_way = false;
      for (const CrowdRobot& r : robots)
        in_way = in_way || InRobotsWay(i, states_[i].position_W, r);
      if (in_way && !giving_way_[i] && time_ >= give_way_retry_[i]) {
        giving_way_[i] = GiveWay(i, robots) ? 1 : 0;
        // no refuge found: look again in a second (each look runs up to 12 A* searches)
        if (!giving_way_[i]) give_way_retry_[i] = time_ + 1.0;
      } else if (!in_way)
        giving_way_[i] = 0;
    }
    preferred[i] = Preferred(i);
    // a robot came into the agent's contact disc: it steps away (a blocker holds still)
    const bool yield = a.behaviour != AgentBehaviour::kBlock &&
                       Touching(i, states_[i].position_W, robots) != nullptr;
    if (yield && !yielding_[i])
      Decide(i, "yield", Touching(i, states_[i].position_W, robots)->position_W);
    yielding_[i] = yield ? 1 : 0;
  }
  // new velocities from the states at the start of the step (a synchronous update)
  std::vector<Eigen::Vector2d> velocity(n, Eigen::Vector2d::Zero());
  std::vector<double> new_speed(n, 0.0);
  std::vector<OrcaLine> lines;
  for (size_t i = 0; i < n; ++i) {
    if (!active_[i]) continue;
    const AgentConfig& a = agents_[i];
    const double own = KindModel(a.kind).disc_radius_m;
    const CrowdAgentState& s = states_[i];
    lines.clear();
    const bool vehicle = IsVehicle(a.kind);
    if (holding_[i]) continue;  // stands still: velocity 0
    for (size_t j = 0; j < n; ++j) {
      if (j == i || !active_[j]) continue;
      Eigen::Vector2d rel = states_[j].position_W - s.position_W;
      // two centres in one place: the lower index steps west, the higher east
      if (rel.norm() < 1e-6) rel = Eigen::Vector2d(j > i ? 1e-3 : -1e-3, 0);
      const double r = own + KindModel(agents_[j].kind).disc_radius_m + kSafetyM;
      if (rel.norm() > kNeighbourM + r) continue;
      const double responsibility = (vehicle || IsVehicle(agents_[j].kind)) ? 1.0 : 0.5;
      lines.push_back(OrcaHalfPlane(s.velocity_W, rel, s.velocity_W - states_[j].velocity_W, r,
                                    kTau, dt_, responsibility));
    }
    AddRobotLines(i, robots, own, s.velocity_W, &lines);
    if (yielding_[i]) {
      // straight away from the robot (a vehicle: along its axis, below)
      const Eigen::Vector2d away = s.position_W - Touching(i, s.position_W, robots)->position_W;
      const Eigen::Vector2d dir =
          away.norm() > 1e-9 ? Eigen::Vector2d(away.normalized()) : Eigen::Vector2d(1, 0);
      if (!vehicle) {
        velocity[i] = dir * a.speed_m_s;
        continue;
      }
      const Eigen::Vector2d axis(std::cos(s.yaw), std::sin(s.yaw));
      velocity[i] =
          (axis.dot(dir) >= 0 ? 1.0 : -1.0) * std::min(a.speed_m_s, kVehicleYieldSpeed) * axis;
      continue;
    }
    if (!vehicle) {
      velocity[i] = SolveOrcaVelocity(lines, a.speed_m_s, preferred[i]);
      continue;
    }
    // vehicle: the speed along its (driving) heading that the half-planes admit
    const double drive_yaw = gear_[i] > 0 ? s.yaw : s.yaw + M_PI;
    const Eigen::Vector2d h(std::cos(drive_yaw), std::sin(drive_yaw));
    double want = preferred[i].norm();
    if (plans_[i].active) {
      // slow for the goal (1 m/s^2) and for sharp turns ahead
      const double to_goal = (plans_[i].goal - s.position_W).norm();
      want = std::min(want, std::sqrt(2.0 * 1.0 * to_goal));
      if (preferred[i].norm() > 1e-9 && preferred[i].normalized().dot(h) < 0.5)
        want = std::min(want, 0.3);
    }
    double lo = 0, hi = a.speed_m_s;
    for (const OrcaLine& l : lines) {
      // det(d, s h - q) >= 0  <=>  s det(d, h) >= det(d, q)
      const double k = l.direction.x() * h.y() - l.direction.y() * h.x();
      const double b = l.direction.x() * l.point.y() - l.direction.y() * l.point.x();
      if (std::abs(k) < 1e-12) {
        if (b > 0) hi = -1;
      } else if (k > 0) {
        lo = std::max(lo, b / k);
      } else {
        hi = std::min(hi, b / k);
      }
    }
    // no speed meets every half-plane: stop, unless only lower bounds conflict (it is inside
    // a neighbour's horizon and driving away from it), then drive away as fast as it may
    double v = lo <= hi ? std::clamp(want, lo, hi) : hi >= a.speed_m_s ? a.speed_m_s : 0.0;
    const double prev = std::abs(speed_[i]);
    v = std::clamp(v, prev - kVehicleAccel * dt_, prev + kVehicleAccel * dt_);
    new_speed[i] = std::max(0.0, v);
  }
  // integrate, keeping every centre on its walkable region and never moving deeper into
  // another agent's disc (the others as far as they moved this step: index order)
  const auto crowds = [&](size_t i, const Eigen::Vector2d& from, const Eigen::Vector2d& to) {
    const double ri = KindModel(agents_[i].kind).disc_radius_m;
    for (size_t j = 0; j < n; ++j) {
      if (j == i || !active_[j]) continue;
      const double r = ri + KindModel(agents_[j].kind).disc_radius_m;
      const double d = (to - states_[j].position_W).norm();
      if (d < r && d < (from - states_[j].position_W).norm()) return true;
    }
    return false;
  };
  for (size_t i = 0; i < n; ++i) {
    if (!active_[i]) continue;
    const AgentConfig& a = agents_[i];
    CrowdAgentState& s = states_[i];
    const WalkableGrid& reg = region(i);
    const Eigen::Vector2d old = s.position_W;
    const auto allowed = [&](const Eigen::Vector2d& c) {
      return reg.Walkable(c) && !crowds(i, old, c) && !EntersRobot(i, old, c, robots);
    };
    if (IsVehicle(a.kind) && yielding_[i]) {
      // backing away from a robot along its axis, heading unchanged
      const Eigen::Vector2d next = old + velocity[i] * dt_;
      if (allowed(next)) s.position_W = next;
      speed_[i] = 0;
    } else if (!IsVehicle(a.kind)) {
      const Eigen::Vector2d step = velocity[i] * dt_;
      // the whole step, along x or y alone, half of it, or none
      Eigen::Vector2d next = old;
      for (const Eigen::Vector2d& c :
           {Eigen::Vector2d(old + step), Eigen::Vector2d(old.x() + step.x(), old.y()),
            Eigen::Vector2d(old.x(), old.y() + step.y()), Eigen::Vector2d(old + 0.5 * step)})
        if (allowed(c)) {
          next = c;
          break;
        }
      s.position_W = next;
      const Eigen::Vector2d moved = next - old;
      if (moved.norm() > 0.05 * dt_) {
        const double turn = WrapAngle(std::atan2(moved.y(), moved.x()) - s.yaw);
        s.yaw = WrapAngle(s.yaw + std::clamp(turn, -kTurnRate * dt_, kTurnRate * dt_));
      }
    } else {
      // kinematic bicycle, pure pursuit of the plan
      const AgentKindModel m = KindModel(a.kind);
      const double drive_yaw = gear_[i] > 0 ? s.yaw : s.yaw + M_PI;
      double curvature = 0;
      const Plan& plan = plans_[i];
      if (plan.active) {
        size_t k = plan.next;
        while (k + 1 < plan.points.size() && (plan.points[k] - old).norm() < kLookAheadM) ++k;
        const Eigen::Vector2d to = plan.points[k] - old;
        const double ld = std::max(to.norm(), 0.1);
        const double alpha = WrapAngle(std::atan2(to.y(), to.x()) - drive_yaw);
        curvature = 2.0 * std::sin(alpha) / ld;
      }
      const double max_curvature = 1.0 / m.walkable.turning_radius_m;
      curvature = std::clamp(curvature, -max_curvature, max_curvature);
      const double steer = std::atan(m.wheelbase_m * curvature);
      const double v = new_speed[i];
      const double yaw_rate = v * std::tan(steer) / m.wheelbase_m;
      const double new_drive_yaw = drive_yaw + yaw_rate * dt_;
      const double mid = drive_yaw + 0.5 * yaw_rate * dt_;
      const Eigen::Vector2d next = old + v * dt_ * Eigen::Vector2d(std::cos(mid), std::sin(mid));
      if (allowed(next)) {
        s.position_W = next;
        s.yaw = WrapAngle(gear_[i] > 0 ? new_drive_yaw : new_drive_yaw - M_PI);
        speed_[i] = v;
      } else {
        speed_[i] = 0;
      }
    }
    s.velocity_W = (s.position_W - old) / dt_;
    if (s.velocity_W.norm() >= 0.1) slow_since_[i] = time_;
  }
  time_ += dt_;
}

}  // namespace penumbra
