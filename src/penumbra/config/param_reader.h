#pragma once
// typed, path-tracking reading of a parsed configuration document (config/config_value.h; a
// YAML or JSON file, config/yaml_document.h, config/json_document.h), for every reader of
// Penumbra's files. every value read through a ParamReader is checked for its type and, where
// asked, its range; a wrong type, a value out of range, an unknown or a duplicate key throws
// ConfigError naming the file, the 1-based line and the key path ("robots[0].pose.xyz").
// the line of every node visited is recorded in a LineTable, so that later semantic
// validation can point at the offending line too.
//
// keys are read once: Find(key) (or Has/Child) marks a key of a mapping as asked for, and
// ReportUnused() then fails on the first key nobody asked for, listing the keys that were
// (as pbrt-v4's ParameterDictionary::ReportUnused). ExpectMap(allowed) is the up-front form
// for blocks whose allowed keys depend on nothing read.

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "penumbra/config/config_value.h"

namespace penumbra {

/// 1-based line of each key path seen while reading a document.
class LineTable {
 public:
  /// remembers that `path` starts on `line` (1-based; lines <= 0 are ignored).
  void Record(const std::string& path, int line);

  /// line of `path`, or of its closest recorded ancestor ("a.b[2].c" -> "a.b[2]" ->
  /// "a.b" -> "a"), or 0 when none is known.
  int Find(const std::string& path) const;

 private:
  std::map<std::string, int> lines_;
};

/// a node of a parsed document together with its key path. cheap to copy; copies share the
/// record of which keys were asked for.
class ParamReader {
 public:
  /// the document root. `file` is used in error messages; `lines` (may be null) receives the
  /// line of every node visited.
  ParamReader(const ConfigValue& root, std::string file, LineTable* lines);

  /// key path of this node ("" for the root).
  const std::string& path() const { return path_; }
  /// 1-based line of this node, 0 when unknown.
  int line() const { return line_; }
  /// the file named in errors.
  const std::string& file() const;
  /// the underlying value.
  const ConfigValue& node() const { return node_; }

  /// throws ConfigError(file, line(), path(), problem).
  [[noreturn]] void Fail(const std::string& problem) const;

  /// checks that the node is a mapping whose keys are unique scalars from `allowed`.
  /// a null node ("key:" with no value) counts as an empty mapping.
  /// @throws ConfigError "expected a mapping", "unknown key 'k'; expected one of: ..."
  ///         (at the key's line), or "key 'k' appears twice".
  void ExpectMap(const std::vector<std::string_view>& allowed) const;

  /// checks that the node is a mapping with unique scalar keys (any names).
  void ExpectMapAnyKeys() const;

  /// checks that the node is a sequence (a null node counts as an empty one).
  /// @throws ConfigError "expected a list".
  void ExpectList() const;

  /// true if this (mapping) node has `key`; marks `key` asked for (ReportUnused).
  bool Has(std::string_view key) const;

  /// child `key` of this mapping. its path is "<path>.<key>" and its line that of the key;
  /// marks `key` asked for. @throws ConfigError "required key 'k' is missing".
  ParamReader Child(std::string_view key) const;

  /// child `key` when present, std::nullopt when absent; marks `key` asked for either way.
  /// the one-read form: `if (auto v = r.Find("rate_hz")) c.rate_hz = v->Double();`
  std::optional<ParamReader> Find(std::string_view key) const;

  /// fails on the first key (in file order) of this mapping that was never asked for through
  /// Has, Child or Find: "unknown key 'k'; expected one of: <the keys asked for, in order>"
  /// at the key's line. checks duplicate and non-scalar keys first (ExpectMapAnyKeys).
  /// nothing to report for a null node.
  void ReportUnused() const;

  /// element `i` of this sequence; path "<path>[i]".
  ParamReader Element(size_t i) const;

  /// number of elements of a sequence or entries of a mapping.
  size_t size() const { return node_.size(); }

  /// entries of a mapping in file order, keyed by their (scalar) key; marks each asked for.
  std::vector<std::pair<std::string, ParamReader>> Entries() const;

  /// a finite real number. @throws ConfigError "expected a number" otherwise.
  double Double() const;
  /// a finite real number in [min, max] (either bound may be infinite).
  /// @throws ConfigError "got X; expected a number in [min, max]" (">= min" / "<= max" for
  ///         one-sided ranges), `unit` appended when not empty.
  double Double(double min, double max, std::string_view unit = {}) const;
  /// an integer in the range of int. @throws ConfigError "expected an integer".
  int Int() const;
  /// an integer in [min, max]. @throws ConfigError "got N; expected an integer in [min, max]".
  int Int(int min, int max) const;
  /// a non-negative integer < 2^64. @throws ConfigError "expected a non-negative integer".
  uint64_t Uint64() const;
  /// true/false (also YAML 1.1 yes/no/on/off). @throws ConfigError "expected true or false".
  bool Bool() const;
  /// any scalar as text. @throws ConfigError "expected a string".
  std::string String() const;
  /// one of `valid`. @throws ConfigError "unknown value 'x'; expected one of: ...".
  std::string Enum(const std::vector<std::string_view>& valid) const;
  /// the value of `table` whose name the scalar is (a closed set read through its table).
  /// @throws ConfigError as Enum, listing the table's names in order.
  template <class E>
  E Enum(const std::vector<std::pair<std::string_view, E>>& table) const {
    std::vector<std::string_view> names;
    names.reserve(table.size());
    for (const auto& [name, value] : table) names.push_back(name);
    const std::string s = Enum(names);
    for (const auto& [name, value] : table)
      if (name == s) return value;
    Fail("unknown value '" + s + "'");  // not reached: Enum accepted one of the names
  }
  /// a list of exactly 3 finite numbers. @throws ConfigError "expected a list of 3 numbers".
  Eigen::Vector3d Vector3() const;
  /// a list of exactly `count` finite numbers (any number when count is 0).
  /// @throws ConfigError "expected a list of N numbers, got ..." or the element's error.
  std::vector<double> Doubles(size_t count = 0) const;
  /// the elements of a sequence. @throws ConfigError "expected a list".
  std::vector<ParamReader> List() const;

 private:
  struct Context;
  ParamReader(ConfigValue node, std::string path, int line, std::shared_ptr<Context> ctx);
  std::string Describe() const { return node_.Describe(); }
  void MarkAsked(std::string_view key) const;

  ConfigValue node_;
  std::string path_;
  int line_ = 0;
  std::shared_ptr<Context> ctx_;
};

/// "a, b, c" from a list of names.
std::string JoinNames(const std::vector<std::string_view>& names);

/// shortest decimal text that round-trips `v` ("0.002", "1e+06", "inf").
std::string FormatNumber(double v);

}  // namespace penumbra
