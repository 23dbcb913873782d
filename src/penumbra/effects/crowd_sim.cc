#include "penumbra/effects/crowd_sim.h"

#include <algorithm>
#include <cmath>

#include "penumbra/core/error.h"
#include "penumbra/effects/agent_animation.h"

namespace penumbra {
namespace {

// key of the crowd's random goal draws (core/rng.h streams)
constexpr uint64_t kCrowdStream = 0xC20D5E1D0ULL;
constexpr double kTau = 2.0;              // ORCA time horizon, s
constexpr double kNeighbourM = 8.0;       // neighbours farther than this are not considered, m
constexpr double kReachedM = 0.2;         // a goal within this is reached (people), m
constexpr double kVehicleReachedM = 0.6;  // ... by a vehicle (its turns are limited), m
constexpr double kWaypointM = 0.3;        // a plan point within this is passed, m
constexpr double kTurnRate = 6.0;         // people's heading rate limit, rad/s
constexpr double kLookAheadM = 1.5;       // pure pursuit look-ahead, m
constexpr double kVehicleAccel = 1.5;     // vehicles' speed change limit, m/s^2
constexpr double kSafetyM = 0.02;         // added to every combined radius, m
constexpr double kBlockReplanSec = 1.0;   // a `block` agent's new block point, s
constexpr double kBlockAheadM = 0.5;      // block point: this far beyond the discs' contact, m
constexpr double kBlockHoldM = 0.5;       // holds while no farther than the block point + this, m

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
      m.walkable = {0.3, 0.1, 2.0, 0.0};
      break;
    case AgentKind::kForklift:
      m.disc_radius_m = 1.2;
      m.walkable = {0.7, 0.05, 2.3, 2.0};
      m.wheelbase_m = AgentWheelbase(kind);
      break;
    case AgentKind::kCart:
      m.disc_radius_m = 0.6;
      m.walkable = {0.45, 0.05, 1.2, 0.8};
      m.wheelbase_m = AgentWheelbase(kind);
      break;
  }
  return m;
}

bool IsVehicle(AgentKind kind) { return kind != AgentKind::kPerson; }

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

void CrowdSim::AddRobotLines(size_t i, const std::vector<CrowdRobot>& robots, double own_radius,
                             const Eigen::Vector2d& v_a, std::vector<OrcaLine>* lines) const {
  const AgentConfig& a = agents_[i];
  if (a.behaviour == AgentBehaviour::kIgnore) return;
  const double extra = a.behaviour == AgentBehaviour::kAvoid ? a.clearance_m : 0.0;
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
    preferred[i] = Preferred(i);
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
    double v = lo <= hi ? std::clamp(want, lo, hi) : 0.0;
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
    if (!IsVehicle(a.kind)) {
      const Eigen::Vector2d step = velocity[i] * dt_;
      // the whole step, along x or y alone, half of it, or none
      Eigen::Vector2d next = old;
      for (const Eigen::Vector2d& c :
           {Eigen::Vector2d(old + step), Eigen::Vector2d(old.x() + step.x(), old.y()),
            Eigen::Vector2d(old.x(), old.y() + step.y()), Eigen::Vector2d(old + 0.5 * step)})
        if (reg.Walkable(c) && !crowds(i, old, c)) {
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
      if (reg.Walkable(next) && !crowds(i, old, next)) {
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
