#pragma once
// typed, validated reading of structured controller parameters: lists of names, per-joint
// numbers, and the mappings inside lists (e.g. one item of a `commands:` script). builds on
// ControllerParams::Raw; every error is a ConfigError in the controller's context naming the
// full key path, e.g. "world.yaml:12: robots[arm].controller.commands[2].xyz: got a list of
// 2 items; expected 3 numbers (m)".

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "penumbra/config/config_value.h"
#include "penumbra/control/controller.h"
#include "penumbra/control/controller_params.h"

namespace penumbra {

/// reader over one mapping that lives inside a controller block. keys read through it
/// are marked known; CheckNoUnknownKeys() rejects the rest. the node must outlive the reader.
class ParamNode {
 public:
  /// @param node    a value (any kind; non-mappings fail on first use)
  /// @param path    its key path relative to the controller block, e.g. "commands[2]"
  /// @param context where the controller block is (file, line, key)
  ParamNode(const ConfigValue& node, std::string path, ControllerContext context);
  ~ParamNode();
  ParamNode(ParamNode&&) noexcept;
  ParamNode(const ParamNode&) = delete;
  ParamNode& operator=(const ParamNode&) = delete;

  /// true when the node is a mapping with `key`.
  bool Has(const std::string& key) const;
  /// finite number in [min, max], required when `fallback` is empty.
  double Number(const std::string& key, std::optional<double> fallback, double min, double max);
  /// exactly `count` finite numbers in [min, max]; `unit` names the unit in messages.
  std::vector<double> Numbers(const std::string& key, size_t count, double min, double max,
                              const std::string& unit);
  /// non-empty scalar string, required.
  std::string String(const std::string& key);
  /// the mapping under `key` (required).
  ParamNode Child(const std::string& key);
  /// the raw value under `key` (nullptr when absent); marks it known.
  const ConfigValue* Raw(const std::string& key);
  /// "<path>.<key>" relative to the controller block.
  std::string KeyPath(const std::string& key) const;

  /// @throws ConfigError listing keys that were never read and the keys that were.
  void CheckNoUnknownKeys() const;
  /// @throws ConfigError for `key` of this node with `problem`.
  [[noreturn]] void Fail(const std::string& key, const std::string& problem) const;
  /// @throws ConfigError for the node itself.
  [[noreturn]] void FailHere(const std::string& problem) const;

  const std::string& path() const { return path_; }
  const ControllerContext& context() const { return context_; }

 private:
  const ConfigValue* Get(const std::string& key);

  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::string path_;
  ControllerContext context_;
};

/// `key`: a list of at least `min_count` distinct non-empty names, each given `prefix`
/// (robot-local MJCF names -> "<robot>/<name>"). @throws ConfigError when missing or bad.
std::vector<std::string> ReadNameList(ControllerParams& params, const std::string& key,
                                      size_t min_count, const std::string& prefix);

/// `key`: one number for every joint, written either as a single number (used for all
/// `count` joints) or as a list of exactly `count` numbers; each in [min, max] (min
/// excluded when `min_exclusive`). `fallback` (one value per joint) applies when the key is
/// absent; without it the key is required. @throws ConfigError naming the key and the range.
std::vector<double> ReadPerJoint(ControllerParams& params, const std::string& key, size_t count,
                                 std::optional<std::vector<double>> fallback, double min,
                                 double max, bool min_exclusive = false);

/// `key`: a list of exactly `count` finite numbers in [min, max], or std::nullopt when the
/// key is absent. @throws ConfigError when present but bad.
std::optional<std::vector<double>> ReadOptionalNumbers(ControllerParams& params,
                                                       const std::string& key, size_t count,
                                                       double min, double max,
                                                       const std::string& unit);

}  // namespace penumbra
