#pragma once
// typed, path-tracking access to a parsed YAML document, for config loaders.
// every value read through a YamlReader is checked for its type; a wrong type,
// an unknown key or a duplicate key throws ConfigError naming the file, the
// 1-based line (from yaml-cpp's Mark) and the key path ("robots[0].pose.xyz").
// the line of every node visited is recorded in a LineTable so that later,
// semantic validation can point at the offending line too.

#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

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

/// a node of a YAML document together with its key path. cheap to copy.
class YamlReader {
 public:
  /// the document root. `file` is used in error messages; `lines` (may be null)
  /// receives the line of every node visited.
  YamlReader(const YAML::Node& root, std::string file, LineTable* lines);

  /// key path of this node ("" for the root).
  const std::string& path() const { return path_; }
  /// 1-based line of this node, 0 when unknown.
  int line() const { return line_; }
  /// the underlying node.
  const YAML::Node& node() const { return node_; }

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

  /// true if this (mapping) node has `key`.
  bool Has(std::string_view key) const;

  /// child `key` of this mapping (call ExpectMap first). its path is "<path>.<key>"
  /// and its line that of the key. @throws ConfigError if the key is missing.
  YamlReader Child(std::string_view key) const;

  /// element `i` of this sequence; path "<path>[i]".
  YamlReader Element(size_t i) const;

  /// number of elements of a sequence or entries of a mapping.
  size_t size() const { return node_.size(); }

  /// entries of a mapping in file order, keyed by their (scalar) key.
  std::vector<std::pair<std::string, YamlReader>> Entries() const;

  /// a finite real number. @throws ConfigError "expected a number" otherwise.
  double Double() const;
  /// an integer in the range of int. @throws ConfigError "expected an integer".
  int Int() const;
  /// a non-negative integer < 2^64. @throws ConfigError "expected a non-negative integer".
  uint64_t Uint64() const;
  /// true/false (also YAML 1.1 yes/no/on/off). @throws ConfigError "expected true or false".
  bool Bool() const;
  /// any scalar as text. @throws ConfigError "expected a string".
  std::string String() const;
  /// one of `valid`. @throws ConfigError "unknown value 'x'; expected one of: ...".
  std::string Enum(const std::vector<std::string_view>& valid) const;
  /// a list of exactly 3 finite numbers. @throws ConfigError "expected a list of 3 numbers".
  Eigen::Vector3d Vector3() const;
  /// the elements of a sequence. @throws ConfigError "expected a list".
  std::vector<YamlReader> List() const;

 private:
  struct Context {
    std::string file;
    LineTable* lines = nullptr;
  };
  YamlReader(YAML::Node node, std::string path, int line, std::shared_ptr<const Context> ctx);
  std::string Describe() const;  // short description of the value, for messages

  YAML::Node node_;
  std::string path_;
  int line_ = 0;
  std::shared_ptr<const Context> ctx_;
};

/// the most YAML documents a reader of Penumbra's files walks: yaml-cpp 0.7 yields empty
/// documents for ever on some short inputs (",sn\xd4 !:"), so every loop over documents stops here
inline constexpr int kMaxYamlDocuments = 1024;

/// refuses YAML tags: every node of every document of `text` must carry no tag (a plain or a
/// quoted value, a mapping or a list as written). Penumbra's files read no tags, so a tag such
/// as `!foo 3`, `!!binary ...` or `!!str 5` would otherwise be dropped without a word.
/// works on the parser's events, so aliases are not expanded.
/// @throws ConfigError(file, line of the tagged node, "", "YAML tag '!foo' ...; expected ...");
///         YAML::ParserException for a syntax error (as YAML::Load).
void RefuseYamlTags(const std::string& text, const std::string& file);

/// "a, b, c" from a list of names.
std::string JoinNames(const std::vector<std::string_view>& names);

/// shortest decimal text that round-trips `v` ("0.002", "1e+06", "inf").
std::string FormatNumber(double v);

}  // namespace penumbra
