#pragma once
// typed, validated access to a controller's parameter map (config/config_value.h) (the
// `controller:` block of a robot in a world file). every error is a ConfigError
// naming the world file, the block's line and the full key path, e.g.
// "world.yaml:12: robots[rover].controller.speed_m_s: got -1; expected a number > 0".

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "penumbra/config/config_value.h"
#include "penumbra/control/controller.h"

namespace penumbra {

/// reader over one controller's parameter map. keys read through it are marked as
/// known; CheckNoUnknownKeys() then rejects anything else (typos fail loudly).
class ControllerParams {
 public:
  /// reads `params` (a mapping, or a null or undefined value for no parameters; the `type` key, if
  /// present, is ignored here). the nodes are shared, not copied; they are only read.
  /// @throws ConfigError if `params` is neither null nor a mapping.
  ControllerParams(const ConfigValue& params, ControllerContext context);
  ~ControllerParams();
  ControllerParams(const ControllerParams&) = delete;
  ControllerParams& operator=(const ControllerParams&) = delete;

  bool Has(const std::string& key) const;
  /// required string. @throws ConfigError if missing, not a scalar or empty.
  std::string String(const std::string& key);
  /// finite number, required when `fallback` is empty; checked against [min, max]
  /// (bounds inclusive unless `min_exclusive`). @throws ConfigError naming the range.
  double Number(const std::string& key, std::optional<double> fallback, double min, double max,
                bool min_exclusive = false);
  /// boolean (true/false), with a default.
  bool Bool(const std::string& key, bool fallback);
  /// list of [x, y] pairs of finite numbers, at least `min_count`.
  std::vector<Eigen::Vector2d> Points2(const std::string& key, size_t min_count);

  /// the value of `key`, for structured values the typed readers above don't cover
  /// (lists of mappings, nested blocks); nullptr when absent. marks `key` as known. the
  /// node lives as long as this object; report bad values with Fail("key[i].sub", ...).
  const ConfigValue* Raw(const std::string& key) { return Get(key); }

  /// @throws ConfigError listing the keys that were never read, and the allowed keys.
  void CheckNoUnknownKeys() const;
  /// @throws ConfigError for `key` (relative to the controller block) with `problem`.
  [[noreturn]] void Fail(const std::string& key, const std::string& problem) const;

  const ControllerContext& context() const { return context_; }

 private:
  const ConfigValue* Get(const std::string& key);

  ControllerContext context_;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// a value described for an error message: 'text', "a list of N items", "a mapping" or
/// "nothing".
std::string DescribeParamNode(const ConfigValue& node);

/// a finite number from `node` (a value under a key that ControllerParams::Raw returned, or an
/// element of one). @throws ConfigError through p.Fail(key, "got ...; expected " + expected).
double ParamNumberAt(ControllerParams& p, const ConfigValue& node, const std::string& key,
                     const std::string& expected);

/// a finite number in [min, max] from `node`; `unit` (may be empty) names the unit in messages.
/// @throws ConfigError through p.Fail naming the range, e.g. "got 1e+300; expected a number in
/// [-100, 100] (m/s)".
double ParamNumberAt(ControllerParams& p, const ConfigValue& node, const std::string& key,
                     double min, double max, const std::string& unit);

/// a number or a list of numbers (at least one) from `node`, each finite and accepted by `ok`;
/// list elements are reported as key[i]. @throws ConfigError through p.Fail.
std::vector<double> ParamNumbersAt(ControllerParams& p, const ConfigValue& node,
                                   const std::string& key, const std::string& expected,
                                   bool (*ok)(double));

}  // namespace penumbra
