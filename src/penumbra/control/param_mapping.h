#pragma once
// what ControllerParams and ParamNode share: the entries of one mapping with the keys
// read so far, and the checks and texts of their error messages. internal to
// src/penumbra/control (the readers turn each problem text into a ConfigError with the key
// path and the controller block's file and line).

#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "penumbra/config/config_value.h"

namespace penumbra {

/// the entries of one mapping, in file order, and the keys read so far.
class ParamMapping {
 public:
  /// takes the entries of `node` when it is a mapping; no entries otherwise.
  void Load(const ConfigValue& node);
  /// marks `key` as known (allowed) without reading it.
  void MarkKnown(const std::string& key) { known_.insert(key); }
  /// true when the mapping has `key`.
  bool Has(const std::string& key) const;
  /// marks `key` known; its value, or nullptr when absent. lives as long as this object.
  const ConfigValue* Get(const std::string& key);
  /// when keys were never read: the first of them and the problem text listing them all and
  /// the known keys; std::nullopt when every key was read.
  std::optional<std::pair<std::string, std::string>> UnknownKeys() const;

 private:
  std::vector<std::pair<std::string, ConfigValue>> entries_;
  std::set<std::string> known_;
};

namespace param {

/// a value as error messages show it: 'text', "a list of N items", "a mapping", "nothing".
std::string Repr(const ConfigValue& n);
/// a number as error messages show it (ostream default format).
std::string FormatNumber(double v);
/// "> min" (min_exclusive) or ">= min", then " and <= max" unless max is infinite.
std::string RangeText(double min, double max, bool min_exclusive);
/// true and *v set when `n` is a scalar that reads as a finite number.
bool ToNumber(const ConfigValue& n, double* v);
/// the problem with `n` as a required name (missing, not a scalar, empty); nullopt if none.
std::optional<std::string> NameProblem(const ConfigValue* n);
/// `n` as a finite number in [min, max] (min excluded when `min_exclusive`), `fallback` when
/// `n` is nullptr. on a problem returns 0 and sets *problem ("missing; expected a number
/// <range>" or "got ...; expected a number <range>"); `range` is the range's text.
double ReadNumber(const ConfigValue* n, std::optional<double> fallback, double min, double max,
                  bool min_exclusive, const std::string& range, std::string* problem);

}  // namespace param
}  // namespace penumbra
