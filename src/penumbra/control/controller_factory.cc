#include "penumbra/control/controller_factory.h"

#include <functional>
#include <map>

#include "penumbra/control/controller_params.h"
#include "penumbra/control/diff_ik.h"
#include "penumbra/control/joint_controller.h"
#include "penumbra/control/keyframe_playback.h"
#include "penumbra/control/multirotor_pid.h"
#include "penumbra/control/policy_controller.h"
#include "penumbra/control/trot_gait.h"
#include "penumbra/control/waypoint_follower.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

using Maker = std::function<std::unique_ptr<Controller>(ControllerParams&, const std::string&,
                                                        const ControllerContext&)>;

// every controller type; a new type adds one entry here.
const std::map<std::string, Maker>& Registry() {
  static const std::map<std::string, Maker> registry = {
      {"joint_pd",
       [](ControllerParams& p, const std::string& prefix, const ControllerContext& c) {
         return std::make_unique<JointPdController>(JointPdParams::Parse(p, prefix), c);
       }},
      {"diff_ik",
       [](ControllerParams& p, const std::string& prefix, const ControllerContext& c) {
         return std::make_unique<DiffIkController>(DiffIkParams::Parse(p, prefix), c);
       }},
      {"keyframe_playback",
       [](ControllerParams& p, const std::string& prefix, const ControllerContext& c) {
         return std::make_unique<KeyframePlayback>(KeyframePlaybackParams::Parse(p, prefix), c);
       }},
      {"policy",
       [](ControllerParams& p, const std::string& prefix, const ControllerContext& c) {
         return std::make_unique<PolicyController>(PolicyParams::Parse(p, prefix), c);
       }},
      {"trot_gait",
       [](ControllerParams& p, const std::string& prefix, const ControllerContext& c) {
         return std::make_unique<TrotGait>(TrotGaitParams::Parse(p, prefix), c);
       }},
      {"multirotor_pid",
       [](ControllerParams& p, const std::string& prefix, const ControllerContext& c) {
         return std::make_unique<MultirotorPid>(MultirotorPidParams::Parse(p, prefix), c);
       }},
      {"waypoint_follower",
       [](ControllerParams& p, const std::string& prefix, const ControllerContext& c) {
         return std::make_unique<WaypointFollower>(WaypointFollowerParams::Parse(p, prefix), c);
       }},
  };
  return registry;
}

}  // namespace

std::vector<std::string> ControllerTypes() {
  std::vector<std::string> types;
  for (const auto& kv : Registry()) types.push_back(kv.first);
  return types;
}

std::unique_ptr<Controller> MakeController(const ControllerConfig& cfg,
                                           const std::string& robot_name,
                                           const std::string& world_file) {
  if (cfg.type.empty()) return nullptr;
  ControllerContext context{
      world_file, cfg.line,
      robot_name.empty() ? "controller" : "robots[" + robot_name + "].controller"};
  const auto it = Registry().find(cfg.type);
  if (it == Registry().end()) {
    std::string known;
    for (const auto& t : ControllerTypes()) known += (known.empty() ? "" : ", ") + t;
    throw ConfigError(world_file, cfg.line, context.key + ".type",
                      "unknown controller type '" + cfg.type + "'; expected one of: " + known);
  }
  ControllerParams params(cfg.params, context);
  const std::string prefix = robot_name.empty() ? "" : robot_name + "/";
  return it->second(params, prefix, context);
}

}  // namespace penumbra
