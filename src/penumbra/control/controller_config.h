#pragma once
// a robot's `controller:` block: which controller type drives it and that controller's
// parameters. world/world_config.cc reads it from a world file; control/controller_factory.h
// builds the controller from it; tests and benchmarks fill it in code.

#include <string>

#include "penumbra/config/config_value.h"

namespace penumbra {

/// a controller attached to a robot. `type` picks the implementation (ControllerTypes() in
/// control/controller_factory.h); `params` holds the rest of the block as parsed values
/// (config/config_value.h), which the controller parses and validates itself at load
/// (control/controller_params.h), so controllers stay pluggable and the world file's values reach
/// them unchanged.
struct ControllerConfig {
  std::string type;  ///< e.g. "waypoint_follower"; empty = none
  /// the block's mapping without its `type` key (a `type` key in it is ignored); a null or
  /// undefined value means no parameters. any other kind of value is rejected by
  /// MakeController. a copy shares the (immutable) values. in code: ParseYaml(text, file)
  /// (config/yaml_document.h).
  ConfigValue params;
  int line = 0;  ///< 1-based line of the block in the world file (0 = unknown / built in code)
};

}  // namespace penumbra
