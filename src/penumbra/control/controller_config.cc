#include "penumbra/control/controller_config.h"

#include <yaml-cpp/yaml.h>

namespace penumbra {

YamlNodeHandle::YamlNodeHandle() : node_(std::make_shared<YAML::Node>()) {}

YamlNodeHandle::YamlNodeHandle(const YAML::Node& node)
    : node_(std::make_shared<YAML::Node>(node)) {}

}  // namespace penumbra
