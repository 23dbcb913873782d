#include "penumbra/campaign/nav_spec.h"

#include <cmath>

#include "penumbra/core/error.h"
#include "penumbra/world/yaml_reader.h"

namespace penumbra {
namespace {

void Range(const char* field, double v, double lo, double hi, bool lo_open) {
  const bool ok = std::isfinite(v) && (lo_open ? v > lo : v >= lo) && v <= hi;
  if (!ok)
    throw ConfigError("", 0, field,
                      "out of range; expected a number in " + std::string(lo_open ? "(" : "[") +
                          FormatNumber(lo) + ", " + FormatNumber(hi) + "]");
}

}  // namespace

void NavEpisode::ValidateOrThrow() const {
  for (const auto& [field, v] :
       {std::pair{"goal", goal_x}, std::pair{"goal", goal_y}, std::pair{"start", start_x},
        std::pair{"start", start_y}, std::pair{"start", start_yaw_deg}})
    if (!std::isfinite(v)) throw ConfigError("", 0, field, "not finite; expected numbers");
  Range("radius", radius_m, 0, 3600, true);
  Range("timeout_sec", timeout_sec, 0, 3600, true);
}

void NavMetricsConfig::ValidateOrThrow() const {
  Range("debounce_sec", debounce_sec, 0, 3600, false);
  Range("min_force_N", min_force_N, 0, 1e9, false);
  Range("pose_rate_hz", pose_rate_hz, 0, 1000, true);
  if (floor.empty()) throw ConfigError("", 0, "floor", "empty; expected a glob such as *floor*");
}

const std::vector<std::string>& NavProfileNames() {
  static const std::vector<std::string> kNames = {"quadruped", "rover"};
  return kNames;
}

NavRobotProfile NavProfile(const std::string& name) {
  // python/penumbra_nav/robots.py holds the same base bodies and fall limits
  if (name == "quadruped") return {"quadruped", "trunk", {"*_foot"}, 0.15, 45};
  if (name == "rover")
    return {"rover", "chassis", {"left_wheel", "right_wheel", "*_tire", "caster"}, -0.1, 45};
  throw ConfigError(
      "", 0, "profile",
      "unknown robot profile '" + SanitizeForMessage(name, 40) + "'; expected quadruped or rover");
}

const std::vector<std::string>& NavMethodPlaceholders() {
  static const std::vector<std::string> kKeys = {
      "penumbra",    "pythonpath", "endpoint",   "goal_x",  "goal_y",  "radius",
      "timeout_sec", "robot",      "robot_name", "out_dir", "workdir", "seed"};
  return kKeys;
}

std::string BundledNavCommand() {
  return "/usr/bin/env PYTHONPATH={pythonpath} /usr/bin/python3 -m penumbra_nav --endpoint "
         "{endpoint} "
         "--goal {goal_x} {goal_y} --radius {radius} --timeout {timeout_sec} --robot {robot} "
         "--robot-name {robot_name} --out {out_dir}/episode.json";
}

}  // namespace penumbra
