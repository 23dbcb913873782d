#include "penumbra/campaign/nav_metrics.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

#include "penumbra/core/error.h"

namespace penumbra {

void NameContactSides(const std::string& robot, std::vector<ContactInterval>* contacts) {
  const std::string prefix = robot + "/";
  const auto name = [&](std::string* side) {
    if (side->rfind(prefix, 0) == 0) {
      *side = robot;
    } else if (side->rfind("agents/", 0) == 0) {
      const size_t part = side->find('/', 7);
      if (part != std::string::npos) side->resize(part);
    }
  };
  for (ContactInterval& c : *contacts) {
    name(&c.a);
    name(&c.b);
  }
}

bool AgentMadeContact(const ContactInterval& c, const std::string& robot) {
  if (robot.empty()) return false;
  const bool robot_is_a = c.a == robot;
  if (!robot_is_a && c.b != robot) return false;
  const std::string& other = robot_is_a ? c.b : c.a;
  if (other.rfind("agents/", 0) != 0) return false;
  const double agent_speed = robot_is_a ? c.b_toward_a_m_s : c.a_toward_b_m_s;
  const double robot_speed = robot_is_a ? c.a_toward_b_m_s : c.b_toward_a_m_s;
  return agent_speed >= kAgentContactMinSpeed && agent_speed > robot_speed;
}

CollisionCounts CountCollisionsByCause(std::vector<ContactInterval> intervals, double debounce_sec,
                                       double until_sec, const std::string& robot) {
  if (!(debounce_sec >= 0)) throw Error("CountCollisions: debounce_sec must be >= 0");
  std::map<std::pair<std::string, std::string>, std::vector<const ContactInterval*>> by_pair;
  for (const ContactInterval& c : intervals) {
    if (!(c.end_sec >= c.start_sec))
      throw Error("CountCollisions: a contact interval ends before it starts");
    if (c.start_sec > until_sec) continue;
    by_pair[std::minmax(c.a, c.b)].push_back(&c);
  }
  CollisionCounts counts;
  for (auto& [pair, list] : by_pair) {
    std::stable_sort(
        list.begin(), list.end(), [](const ContactInterval* x, const ContactInterval* y) {
          return std::pair(x->start_sec, x->end_sec) < std::pair(y->start_sec, y->end_sec);
        });
    double end = 0;
    for (size_t i = 0; i < list.size(); ++i) {
      if (i == 0 || list[i]->start_sec - end >= debounce_sec) {
        (AgentMadeContact(*list[i], robot) ? counts.agent : counts.robot) += 1;
        end = list[i]->end_sec;
      } else {
        end = std::max(end, list[i]->end_sec);
      }
    }
  }
  return counts;
}

int CountCollisions(std::vector<ContactInterval> intervals, double debounce_sec, double until_sec) {
  if (!(debounce_sec >= 0)) throw Error("CountCollisions: debounce_sec must be >= 0");
  std::map<std::pair<std::string, std::string>, std::vector<std::pair<double, double>>> by_pair;
  for (ContactInterval& c : intervals) {
    if (!(c.end_sec >= c.start_sec))
      throw Error("CountCollisions: a contact interval ends before it starts");
    if (c.start_sec > until_sec) continue;
    if (c.b < c.a) std::swap(c.a, c.b);
    by_pair[{c.a, c.b}].push_back({c.start_sec, c.end_sec});
  }
  int count = 0;
  for (auto& [pair, list] : by_pair) {
    std::sort(list.begin(), list.end());
    double end = 0;
    for (size_t i = 0; i < list.size(); ++i) {
      if (i == 0 || list[i].first - end >= debounce_sec) {
        ++count;
        end = list[i].second;
      } else {
        end = std::max(end, list[i].second);
      }
    }
  }
  return count;
}

NavEpisodeMetrics EvaluateNavEpisode(const std::vector<NavPoseSample>& poses,
                                     const std::vector<ContactInterval>& contacts,
                                     const NavEpisodeTask& task, bool method_ok) {
  if (poses.empty()) throw Error("EvaluateNavEpisode: no pose samples");
  NavEpisodeMetrics m;
  const double t0 = poses.front().time_sec;
  const auto dist = [&](const NavPoseSample& p) {
    return std::hypot(p.x - task.goal_x, p.y - task.goal_y);
  };
  size_t end = poses.size() - 1;
  for (size_t i = 0; i < poses.size(); ++i) {
    const NavPoseSample& p = poses[i];
    if (i > 0 && !(p.time_sec >= poses[i - 1].time_sec))
      throw Error("EvaluateNavEpisode: pose samples out of time order");
    // roll and pitch of X_WB (ZYX Euler angles), deg
    const double roll =
        std::atan2(2 * (p.qw * p.qx + p.qy * p.qz), 1 - 2 * (p.qx * p.qx + p.qy * p.qy)) * 180 /
        M_PI;
    const double pitch =
        std::asin(std::clamp(2 * (p.qw * p.qy - p.qz * p.qx), -1.0, 1.0)) * 180 / M_PI;
    const bool fall = p.z < task.fall_height_m || std::abs(roll) > task.max_tilt_deg ||
                      std::abs(pitch) > task.max_tilt_deg;
    if (i > 0) m.path_length_m += std::hypot(p.x - poses[i - 1].x, p.y - poses[i - 1].y);
    if (m.time_to_goal_sec < 0 && dist(p) <= task.radius_m) m.time_to_goal_sec = p.time_sec - t0;
    if (fall) {
      m.fell = true;
      m.fall_time_sec = p.time_sec;
      end = i;
      break;
    }
    if (p.time_sec - t0 >= task.timeout_sec - 1e-9) {
      end = i;
      break;
    }
  }
  const NavPoseSample& last = poses[end];
  m.final_goal_distance_m = dist(last);
  m.episode_time_sec = last.time_sec - t0;
  const CollisionCounts counts =
      CountCollisionsByCause(contacts, task.debounce_sec, last.time_sec, task.robot);
  m.collisions = counts.robot;
  m.agent_contacts = counts.agent;
  m.success = method_ok && !m.fell && m.final_goal_distance_m <= task.radius_m;
  if (!m.success) m.time_to_goal_sec = -1;
  m.sc = m.success ? 1.0 / (1.0 + m.collisions) : 0.0;
  return m;
}

double SuccessWeightedByCollisions(const std::vector<bool>& success,
                                   const std::vector<int>& collisions) {
  if (success.size() != collisions.size())
    throw Error("SuccessWeightedByCollisions: one collision count per episode expected");
  if (success.empty()) return NAN;
  double sum = 0;
  for (size_t i = 0; i < success.size(); ++i) {
    if (collisions[i] < 0) throw Error("SuccessWeightedByCollisions: negative collision count");
    sum += (success[i] ? 1.0 : 0.0) / (1.0 + collisions[i]);
  }
  return sum / static_cast<double>(success.size());
}

}  // namespace penumbra
