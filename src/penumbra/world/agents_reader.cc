#include "penumbra/world/agents_reader.h"

#include <map>
#include <set>

#include "penumbra/core/error.h"
#include "penumbra/scene/scene_limits.h"

namespace penumbra {
namespace {

Eigen::Vector2d ReadPoint(const ParamReader& r) {
  if (!r.node().IsSequence() || r.size() != 2)
    r.Fail("expected a floor point [x, y] (2 numbers, m)");
  return {r.Element(0).Double(), r.Element(1).Double()};
}

}  // namespace

std::vector<AgentConfig> ReadAgents(const ParamReader& list, const std::string& file) {
  // counted before any is read (scene/scene_limits.h: what MuJoCo's collision detection holds)
  if (list.node().IsSequence() && list.size() > static_cast<size_t>(kMaxAgents))
    list.Fail(std::to_string(list.size()) + " agents; expected at most " +
              std::to_string(kMaxAgents) +
              " (with an adversity preset's NPCs; MuJoCo's collision detection needs memory "
              "that grows with the square of the bodies)");
  std::vector<AgentConfig> agents;
  std::map<std::string, int> lines;  // key path -> line, for validation messages
  const auto note = [&](const ParamReader& r) {
    lines[r.path()] = r.line();
    return r;
  };
  for (const ParamReader& r : list.List()) {
    note(r);
    r.ExpectMap({"name", "type", "waypoints", "speed_m_s", "pause_sec", "start_delay_sec", "route",
                 "floor_z", "height_m", "motion", "behaviour", "goals", "clearance_m", "contact"});
    AgentConfig a;
    a.line = r.line();
    a.name = note(r.Child("name")).String();
    if (r.Has("type")) {
      const std::string t = note(r.Child("type")).Enum({"person", "forklift", "cart"});
      a.kind = t == "person"     ? AgentKind::kPerson
               : t == "forklift" ? AgentKind::kForklift
                                 : AgentKind::kCart;
    }
    const ParamReader w = note(r.Child("waypoints"));
    for (const ParamReader& p : w.List()) a.waypoints.push_back(ReadPoint(note(p)));
    if (const auto found = r.Find("speed_m_s")) a.speed_m_s = note(*found).Double();
    if (const auto found = r.Find("pause_sec")) a.pause_sec = note(*found).Double();
    if (const auto found = r.Find("start_delay_sec")) a.start_delay_sec = note(*found).Double();
    if (r.Has("route")) {
      const std::string t = note(r.Child("route")).Enum({"loop", "pingpong", "once"});
      a.route = t == "loop"       ? AgentRoute::kLoop
                : t == "pingpong" ? AgentRoute::kPingPong
                                  : AgentRoute::kOnce;
    }
    if (const auto found = r.Find("floor_z")) a.floor_z = note(*found).Double();
    if (r.Has("height_m")) {
      a.height_m = note(r.Child("height_m")).Double();
      a.height_given = true;
    }
    if (r.Has("motion"))
      a.motion = note(r.Child("motion")).Enum({"scripted", "crowd"}) == "crowd"
                     ? AgentMotion::kCrowd
                     : AgentMotion::kScripted;
    if (r.Has("behaviour")) {
      const std::string b = note(r.Child("behaviour")).Enum({"avoid", "ignore", "block"});
      a.behaviour = b == "avoid"    ? AgentBehaviour::kAvoid
                    : b == "ignore" ? AgentBehaviour::kIgnore
                                    : AgentBehaviour::kBlock;
    }
    if (r.Has("goals"))
      a.goals = note(r.Child("goals")).Enum({"patrol", "random"}) == "random" ? AgentGoals::kRandom
                                                                              : AgentGoals::kPatrol;
    if (const auto found = r.Find("clearance_m")) a.clearance_m = note(*found).Double();
    if (const auto found = r.Find("contact")) a.robot_contact = note(*found).Bool();
    a.ValidateOrThrow(file, r.path(), [&](const std::string& key) {
      auto it = lines.find(key);
      return it == lines.end() ? 0 : it->second;
    });
    agents.push_back(std::move(a));
  }
  std::map<std::string, size_t> seen;
  for (size_t i = 0; i < agents.size(); ++i) {
    auto [it, fresh] = seen.emplace(agents[i].name, i);
    if (!fresh) {
      const std::string key = "agents[" + std::to_string(i) + "].name";
      throw ConfigError(file, lines.count(key) ? lines[key] : agents[i].line, key,
                        "duplicate agent name '" + agents[i].name + "' (also agents[" +
                            std::to_string(it->second) +
                            "].name); expected names unique among agents");
    }
  }
  return agents;
}

}  // namespace penumbra
