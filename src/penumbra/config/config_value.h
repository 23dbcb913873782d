#pragma once
// a parsed configuration document (a YAML or JSON file) as a tree that no parser's headers
// leak from: null, scalar (text), list or mapping, each with the 1-based line it starts on.
// the backends (config/yaml_document.h, config/json_document.h) build it; ParamReader
// (config/param_reader.h) and the controllers' parameter readers (control/) read it.
// ConfigValue is a cheap handle (copies share the node); a built tree is never changed.

#include <cstddef>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace penumbra {

/// what a node holds. kUndefined is the answer of a lookup that found nothing (a missing key
/// or an index past the end); documents themselves hold no undefined nodes.
enum class ConfigKind { kUndefined, kNull, kScalar, kList, kMap };

class ConfigValue;

/// one entry of a mapping, in file order. keys that were not scalars in the file (a YAML
/// list or mapping used as a key) keep `key_is_scalar` false and an empty `key`.
struct ConfigEntry {
  std::string key;
  bool key_is_scalar = true;
  int key_line = 0;  ///< 1-based line of the key, 0 when unknown
  std::shared_ptr<const struct ConfigNode> value;
};

/// the storage of one node (built by the backends; read through ConfigValue).
struct ConfigNode {
  ConfigKind kind = ConfigKind::kNull;
  std::string scalar;   ///< the text of a scalar (a JSON number as written, bool as true/false)
  bool quoted = false;  ///< a quoted YAML scalar or a JSON string: text, never a number or bool
  bool flow = false;    ///< a list or mapping in flow style ([a, b], {k: v}; every JSON one)
  int line = 0;         ///< 1-based line where the node starts, 0 when unknown
  std::vector<std::shared_ptr<const ConfigNode>> items;  ///< elements of a list
  std::vector<ConfigEntry> entries;                      ///< entries of a mapping, file order
};

/// a handle to a node of a parsed document (or to nothing: IsDefined() false). the accessors
/// follow yaml-cpp's names so readers written against YAML::Node read the same.
class ConfigValue {
 public:
  /// an undefined value (no node)
  ConfigValue() = default;
  /// a handle to `node` (nullptr = undefined)
  explicit ConfigValue(std::shared_ptr<const ConfigNode> node) : node_(std::move(node)) {}

  /// a null node (`key:` with nothing after it), defined.
  static ConfigValue Null(int line = 0);
  /// a plain scalar holding `text`.
  static ConfigValue Scalar(std::string text, int line = 0);
  /// an empty mapping.
  static ConfigValue Map(int line = 0);

  ConfigKind kind() const { return node_ ? node_->kind : ConfigKind::kUndefined; }
  /// false for a missing key or index (and a default-constructed value).
  bool IsDefined() const { return node_ != nullptr; }
  explicit operator bool() const { return IsDefined(); }
  bool IsNull() const { return kind() == ConfigKind::kNull; }
  bool IsScalar() const { return kind() == ConfigKind::kScalar; }
  bool IsSequence() const { return kind() == ConfigKind::kList; }
  bool IsMap() const { return kind() == ConfigKind::kMap; }
  /// a scalar written in quotes (YAML) or a JSON string: reads as text only.
  bool IsQuoted() const { return node_ && node_->quoted; }
  /// a list or mapping written in flow style (`[a, b]`, `{k: v}`, any JSON list or object).
  bool IsFlow() const { return node_ && node_->flow; }

  /// the text of a scalar ("" for any other node).
  const std::string& Scalar() const;
  /// 1-based line where the node starts, 0 when unknown or undefined.
  int line() const { return node_ ? node_->line : 0; }
  /// elements of a list or entries of a mapping; 0 otherwise.
  size_t size() const;

  /// element `i` of a list; undefined when out of range or not a list.
  ConfigValue operator[](size_t i) const;
  /// the value of the first entry `key` of a mapping; undefined when absent or not a mapping.
  ConfigValue operator[](std::string_view key) const;
  ConfigValue operator[](const char* key) const { return (*this)[std::string_view(key)]; }
  /// element `i` (an int index, so that `v[0]` is not read as a null key)
  ConfigValue operator[](int i) const {
    return i < 0 ? ConfigValue() : (*this)[static_cast<size_t>(i)];
  }
  /// the entries of a mapping as (key, value) pairs in file order, the key a scalar value
  /// (as yaml-cpp's iteration over a map: `for (const auto& kv : v.pairs()) kv.first.Scalar()`)
  std::vector<std::pair<ConfigValue, ConfigValue>> pairs() const;
  /// the entries of a mapping in file order (empty for any other node).
  const std::vector<ConfigEntry>& entries() const;

  /// a plain scalar that reads as a number (C++ from_chars rules, a leading '+' allowed):
  /// true and *v set; false otherwise (*v unchanged). inf and nan read (check finiteness).
  bool ToDouble(double* v) const;
  /// a plain or quoted scalar read as a number the way yaml-cpp's as<double>() does (quotes
  /// ignored; '.inf', '.nan' read): the rule of the controllers' parameter readers.
  bool ToDoubleLoose(double* v) const;
  /// a plain scalar that is a YAML 1.1 boolean (true/false, yes/no, on/off, y/n in lower,
  /// Capitalised or UPPER case, as yaml-cpp's convert<bool>): true and *v set.
  bool ToBool(bool* v) const;
  /// ToBool over a quoted scalar too (yaml-cpp's as<bool>() ignores quotes).
  bool ToBoolLoose(bool* v) const;

  /// 'text' / the quoted string "text" / "a list" / "a mapping" / "nothing": the value as an
  /// error message shows it.
  std::string Describe() const;

  /// the node (nullptr when undefined): for building derived trees (e.g. a mapping without
  /// one key) that share the rest.
  const std::shared_ptr<const ConfigNode>& node() const { return node_; }

 private:
  std::shared_ptr<const ConfigNode> node_;
};

/// a mapping with `base`'s entries and `value` under `key` (replacing an entry of that name,
/// else appended): for merging documents (presets, overrides) without changing either.
/// `base` null or undefined counts as an empty mapping.
ConfigValue WithEntry(const ConfigValue& base, const std::string& key, const ConfigValue& value);

/// a mapping with `base`'s entries except those named `key`.
ConfigValue WithoutEntry(const ConfigValue& base, std::string_view key);

}  // namespace penumbra
