#include "penumbra/control/controller_capabilities.h"

#include "penumbra/control/controller.h"

namespace penumbra {

// cross-casts to the interfaces: the one place that asks a controller what it implements
TwistTarget* AsTwistTarget(Controller& c) { return dynamic_cast<TwistTarget*>(&c); }
WaypointTarget* AsWaypointTarget(Controller& c) { return dynamic_cast<WaypointTarget*>(&c); }
JointTarget* AsJointTarget(Controller& c) { return dynamic_cast<JointTarget*>(&c); }
const TwistTarget* AsTwistTarget(const Controller& c) {
  return dynamic_cast<const TwistTarget*>(&c);
}
const WaypointTarget* AsWaypointTarget(const Controller& c) {
  return dynamic_cast<const WaypointTarget*>(&c);
}
const JointTarget* AsJointTarget(const Controller& c) {
  return dynamic_cast<const JointTarget*>(&c);
}
TerrainRayCasterUser* AsTerrainRayCasterUser(Controller& c) {
  return dynamic_cast<TerrainRayCasterUser*>(&c);
}

std::vector<std::string> ControllerCommands(const Controller& c) {
  std::vector<std::string> commands;
  if (AsTwistTarget(c)) commands.push_back("twist");
  if (AsWaypointTarget(c)) commands.push_back("waypoints");
  if (AsJointTarget(c)) commands.push_back("joint_targets");
  return commands;
}

}  // namespace penumbra
