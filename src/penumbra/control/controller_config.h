#pragma once
// a robot's `controller:` block: which controller type drives it and that controller's
// parameters. world/world_config.cc reads it from a world file; control/controller_factory.h
// builds the controller from it; tests and benchmarks fill it in code.

#include <memory>
#include <string>

namespace YAML {
class Node;
}  // namespace YAML

namespace penumbra {

/// a yaml-cpp node held through a pointer, so that a header can carry one without including
/// yaml-cpp (world_config.h reaches most translation units; yaml-cpp's headers are ~25k
/// preprocessed lines). copies share the node, as yaml-cpp's own node handles do. the files that
/// read or write the node include <yaml-cpp/yaml.h> themselves; definitions in
/// controller_config.cc.
class YamlNodeHandle {
 public:
  /// a null node
  YamlNodeHandle();
  /// a handle to `node`'s document (implicit, so `params = YAML::Load(text)` reads as before)
  YamlNodeHandle(const YAML::Node& node);  // NOLINT(google-explicit-constructor)
  /// the node: never a null pointer (a null *node* where none was set)
  const YAML::Node& node() const { return *node_; }
  YAML::Node& node() { return *node_; }
  /// reads as the node wherever a `const YAML::Node&` is expected
  operator const YAML::Node&() const { return *node_; }  // NOLINT(google-explicit-constructor)

 private:
  std::shared_ptr<YAML::Node> node_;
};

/// a controller attached to a robot. `type` picks the implementation (ControllerTypes() in
/// control/controller_factory.h); `params` holds the rest of the block as YAML nodes, which the
/// controller parses and validates itself at load (control/controller_params.h), so controllers
/// stay pluggable and the world file's nodes reach them unchanged.
struct ControllerConfig {
  std::string type;  ///< e.g. "waypoint_follower"; empty = none
  /// the block's mapping without its `type` key (a `type` key in it is ignored); a null node
  /// means no parameters. any other kind of node is rejected by MakeController. a copy shares
  /// the nodes (yaml-cpp nodes are handles); nothing reading it modifies them.
  YamlNodeHandle params;
  int line = 0;  ///< 1-based line of the block in the world file (0 = unknown / built in code)
};

}  // namespace penumbra
