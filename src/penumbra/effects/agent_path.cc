#include "penumbra/effects/agent_path.h"

#include <algorithm>
#include <cmath>
#include <regex>
#include <set>

#include "penumbra/core/error.h"
#include "penumbra/core/number_text.h"
#include "penumbra/core/text_match.h"
#include "penumbra/scene/scene_limits.h"

namespace penumbra {

const char* AgentKindName(AgentKind kind) {
  switch (kind) {
    case AgentKind::kPerson:
      return "person";
    case AgentKind::kForklift:
      return "forklift";
    case AgentKind::kCart:
      return "cart";
  }
  return "?";
}

const char* AgentRouteName(AgentRoute route) {
  switch (route) {
    case AgentRoute::kLoop:
      return "loop";
    case AgentRoute::kPingPong:
      return "pingpong";
    case AgentRoute::kOnce:
      return "once";
  }
  return "?";
}

const char* AgentMotionName(AgentMotion motion) {
  return motion == AgentMotion::kCrowd ? "crowd" : "scripted";
}

const char* AgentBehaviourName(AgentBehaviour behaviour) {
  switch (behaviour) {
    case AgentBehaviour::kAvoid:
      return "avoid";
    case AgentBehaviour::kIgnore:
      return "ignore";
    case AgentBehaviour::kBlock:
      return "block";
  }
  return "?";
}

const char* AgentGoalsName(AgentGoals goals) {
  return goals == AgentGoals::kRandom ? "random" : "patrol";
}

int AgentSemanticClass(AgentKind kind) {
  return kind == AgentKind::kPerson ? kSemanticClassPerson : kSemanticClassVehicle;
}

void AgentConfig::ValidateOrThrow(const std::string& file, const std::string& key_prefix,
                                  const std::function<int(const std::string&)>& line_of) const {
  const auto fail = [&](const std::string& key, const std::string& problem) {
    const std::string path = key_prefix + "." + key;
    const int at = line_of ? line_of(path) : 0;
    throw ConfigError(file, at > 0 ? at : line, path, problem);
  };
  static const std::regex kName("[A-Za-z0-9_-]+");
  if (auto problem = NameLengthProblem(name)) fail("name", *problem);
  if (!std::regex_match(name, kName))
    fail("name", "'" + name + "' is not a valid name; expected letters, digits, '_' and '-'");
  if (waypoints.size() < 2)
    fail("waypoints", "agent '" + name + "' has " + std::to_string(waypoints.size()) +
                          " waypoint(s); expected a list of at least 2 [x, y] points");
  for (size_t i = 0; i < waypoints.size(); ++i) {
    if (!(waypoints[i].allFinite() && waypoints[i].cwiseAbs().maxCoeff() <= kMaxPositionM))
      fail("waypoints[" + std::to_string(i) + "]",
           "[" + FormatG(waypoints[i].x()) + ", " + FormatG(waypoints[i].y()) +
               "] is out of range; expected [x, y] in m, each in [-" + FormatG(kMaxPositionM) +
               ", " + FormatG(kMaxPositionM) + "]");
    if (i > 0 && (waypoints[i] - waypoints[i - 1]).norm() < 0.01)
      fail("waypoints[" + std::to_string(i) + "]",
           "closer than 1 cm to waypoints[" + std::to_string(i - 1) +
               "]; expected consecutive waypoints at least 0.01 m apart");
  }
  if (route == AgentRoute::kLoop && (waypoints.front() - waypoints.back()).norm() < 0.01 &&
      waypoints.size() == 2)
    fail("waypoints", "a loop of two equal points; expected distinct waypoints");
  if (!(std::isfinite(speed_m_s) && speed_m_s > 0 && speed_m_s <= 20))
    fail("speed_m_s", "got " + FormatG(speed_m_s) + "; expected (0, 20] m/s");
  if (!(std::isfinite(pause_sec) && pause_sec >= 0 && pause_sec <= 3600))
    fail("pause_sec", "got " + FormatG(pause_sec) + "; expected [0, 3600] s");
  if (!(std::isfinite(start_delay_sec) && start_delay_sec >= 0 && start_delay_sec <= 3600))
    fail("start_delay_sec", "got " + FormatG(start_delay_sec) + "; expected [0, 3600] s");
  if (!(std::isfinite(floor_z) && std::abs(floor_z) <= kMaxPositionM))
    fail("floor_z", "got " + FormatG(floor_z) + "; expected a height in [-" +
                        FormatG(kMaxPositionM) + ", " + FormatG(kMaxPositionM) + "] m");
  if (!(std::isfinite(height_m) && height_m >= 0.5 && height_m <= 2.5))
    fail("height_m", "got " + FormatG(height_m) + "; expected [0.5, 2.5] m");
  if (!(std::isfinite(clearance_m) && clearance_m >= 0 && clearance_m <= 10))
    fail("clearance_m", "got " + FormatG(clearance_m) + "; expected [0, 10] m");
}

void ValidateAgentsOrThrow(const std::vector<AgentConfig>& agents, const std::string& file) {
  std::set<std::string> names;
  for (size_t i = 0; i < agents.size(); ++i) {
    const std::string prefix = "agents[" + std::to_string(i) + "]";
    agents[i].ValidateOrThrow(file, prefix);
    if (!names.insert(agents[i].name).second)
      throw ConfigError(
          file, agents[i].line, prefix + ".name",
          "duplicate agent name '" + agents[i].name + "'; expected names unique among agents");
  }
}

AgentPath::AgentPath(const AgentConfig& config) : config_(config) {
  config_.ValidateOrThrow("", "agents['" + config.name + "']");
  // the points visited in one cycle, in order
  std::vector<Eigen::Vector2d> pts = config_.waypoints;
  if (config_.route == AgentRoute::kLoop) {
    pts.push_back(pts.front());
  } else if (config_.route == AgentRoute::kPingPong) {
    for (int i = static_cast<int>(config_.waypoints.size()) - 2; i >= 0; --i)
      pts.push_back(config_.waypoints[i]);
  }
  double t = 0;
  for (size_t i = 0; i + 1 < pts.size(); ++i) {
    Leg leg;
    leg.from = pts[i];
    leg.to = pts[i + 1];
    const Eigen::Vector2d d = leg.to - leg.from;
    leg.yaw = std::atan2(d.y(), d.x());
    leg.t_start = t;
    leg.t_arrive = t + d.norm() / config_.speed_m_s;
    leg.t_end = leg.t_arrive + config_.pause_sec;
    t = leg.t_end;
    legs_.push_back(leg);
  }
  cycle_sec_ = t;
}

const AgentPath::Leg& AgentPath::LegAt(double u, double* local) const {
  // first leg whose end lies after u
  auto it = std::upper_bound(legs_.begin(), legs_.end(), u,
                             [](double v, const Leg& leg) { return v < leg.t_end; });
  if (it == legs_.end()) it = legs_.end() - 1;
  *local = u;
  return *it;
}

Eigen::Vector3d AgentPath::Position(double time_sec) const {
  Eigen::Vector2d p;
  double u = std::max(0.0, time_sec) - config_.start_delay_sec;
  if (u <= 0) {
    p = legs_.front().from;
  } else if (config_.route == AgentRoute::kOnce && u >= cycle_sec_) {
    p = legs_.back().to;
  } else {
    if (config_.route != AgentRoute::kOnce) u = std::fmod(u, cycle_sec_);
    double local = 0;
    const Leg& leg = LegAt(u, &local);
    if (local >= leg.t_arrive) {
      p = leg.to;
    } else {
      const double s = (local - leg.t_start) / (leg.t_arrive - leg.t_start);
      p = leg.from + s * (leg.to - leg.from);
    }
  }
  return {p.x(), p.y(), config_.floor_z};
}

double AgentPath::Yaw(double time_sec) const {
  double u = std::max(0.0, time_sec) - config_.start_delay_sec;
  if (u <= 0) return legs_.front().yaw;
  if (config_.route == AgentRoute::kOnce && u >= cycle_sec_) return legs_.back().yaw;
  if (config_.route != AgentRoute::kOnce) u = std::fmod(u, cycle_sec_);
  double local = 0;
  return LegAt(u, &local).yaw;
}

Pose AgentPath::X_WA(double time_sec) const {
  Pose X = Pose::Identity();
  X.linear() = Eigen::AngleAxisd(Yaw(time_sec), Eigen::Vector3d::UnitZ()).toRotationMatrix();
  X.translation() = Position(time_sec);
  return X;
}

}  // namespace penumbra
