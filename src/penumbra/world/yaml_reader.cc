#include "penumbra/world/yaml_reader.h"

#include <yaml-cpp/eventhandler.h>

#include <charconv>
#include <cmath>
#include <limits>
#include <sstream>

#include "penumbra/core/error.h"

namespace penumbra {

void LineTable::Record(const std::string& path, int line) {
  if (line > 0) lines_.emplace(path, line);
}

int LineTable::Find(const std::string& path) const {
  std::string p = path;
  while (true) {
    auto it = lines_.find(p);
    if (it != lines_.end()) return it->second;
    if (p.empty()) return 0;
    // strip the last component: ".key" or "[index]"
    size_t cut = p.find_last_of(".[");
    p = cut == std::string::npos ? std::string() : p.substr(0, cut);
  }
}

std::string JoinNames(const std::vector<std::string_view>& names) {
  std::string s;
  for (std::string_view n : names) {
    if (!s.empty()) s += ", ";
    s += n;
  }
  return s;
}

std::string FormatNumber(double v) {
  char buf[64];
  auto r = std::to_chars(buf, buf + sizeof(buf), v);
  return std::string(buf, r.ptr);
}

namespace {

int MarkLine(const YAML::Mark& mark) { return mark.is_null() ? 0 : mark.line + 1; }

// plain (unquoted) scalars only: a quoted "5" is a string in YAML, not a number.
bool IsPlainScalar(const YAML::Node& n) { return n.IsScalar() && n.Tag() != "!"; }

// the parser's events of a document, refusing the first node with a tag of its own. yaml-cpp
// gives untagged nodes the non-specific tags "?" (plain scalars, mappings, lists) and "!"
// (quoted scalars); anything else was written in the file.
class TagRefuser : public YAML::EventHandler {
 public:
  explicit TagRefuser(const std::string& file) : file_(file) {}
  void OnDocumentStart(const YAML::Mark&) override {}
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark&, YAML::anchor_t) override {}
  void OnScalar(const YAML::Mark& mark, const std::string& tag, YAML::anchor_t,
                const std::string&) override {
    Check(mark, tag);
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string& tag, YAML::anchor_t,
                       YAML::EmitterStyle::value) override {
    Check(mark, tag);
  }
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark& mark, const std::string& tag, YAML::anchor_t,
                  YAML::EmitterStyle::value) override {
    Check(mark, tag);
  }
  void OnMapEnd() override {}

 private:
  void Check(const YAML::Mark& mark, const std::string& tag) const {
    if (tag.empty() || tag == "?" || tag == "!") return;
    // yaml-cpp expands the standard "!!" handle
    const std::string kStandard = "tag:yaml.org,2002:";
    const std::string shown =
        tag.rfind(kStandard, 0) == 0 ? "!!" + tag.substr(kStandard.size()) : tag;
    throw ConfigError(file_, MarkLine(mark), "",
                      "YAML tag '" + shown +
                          "' is not supported; expected a plain value, list or mapping without a "
                          "tag (Penumbra reads no YAML tags: remove it)");
  }
  const std::string& file_;
};

}  // namespace

void RefuseYamlTags(const std::string& text, const std::string& file) {
  std::istringstream in(text);
  YAML::Parser parser(in);
  TagRefuser refuser(file);
  // at most kMaxYamlDocuments documents: yaml-cpp 0.7 yields empty documents for ever on some
  // short inputs (",sn\xd4 !:", found by fuzz/world_fuzz.cc)
  for (int d = 0; d < kMaxYamlDocuments; ++d)
    if (!parser.HandleNextDocument(refuser)) break;
}

YamlReader::YamlReader(const YAML::Node& root, std::string file, LineTable* lines)
    : node_(root), path_(), line_(MarkLine(root.Mark())) {
  auto ctx = std::make_shared<Context>();
  ctx->file = std::move(file);
  ctx->lines = lines;
  ctx_ = std::move(ctx);
  if (line_ == 0) line_ = 1;
  if (ctx_->lines) ctx_->lines->Record(path_, line_);
}

YamlReader::YamlReader(YAML::Node node, std::string path, int line,
                       std::shared_ptr<const Context> ctx)
    : node_(std::move(node)), path_(std::move(path)), line_(line), ctx_(std::move(ctx)) {
  if (ctx_->lines) ctx_->lines->Record(path_, line_);
}

void YamlReader::Fail(const std::string& problem) const {
  throw ConfigError(ctx_->file, line_, path_, problem);
}

std::string YamlReader::Describe() const {
  switch (node_.Type()) {
    case YAML::NodeType::Null:
    case YAML::NodeType::Undefined:
      return "nothing";
    case YAML::NodeType::Scalar:
      if (node_.Tag() == "!") return "the quoted string \"" + node_.Scalar() + "\"";
      return "'" + node_.Scalar() + "'";
    case YAML::NodeType::Sequence:
      return "a list";
    case YAML::NodeType::Map:
      return "a mapping";
  }
  return "?";
}

void YamlReader::ExpectMapAnyKeys() const {
  if (node_.IsNull()) return;  // "key:" with no value = an empty mapping
  if (!node_.IsMap()) Fail("expected a mapping (key: value pairs), got " + Describe());
  std::map<std::string, int> seen;
  for (auto it = node_.begin(); it != node_.end(); ++it) {
    const int key_line = MarkLine(it->first.Mark());
    if (!it->first.IsScalar()) {
      throw ConfigError(ctx_->file, key_line ? key_line : line_, path_,
                        "expected a key name, got a list or mapping as a key");
    }
    const std::string& key = it->first.Scalar();
    auto [prev, inserted] = seen.emplace(key, key_line);
    if (!inserted) {
      throw ConfigError(ctx_->file, key_line ? key_line : line_,
                        path_.empty() ? key : path_ + "." + key,
                        "key '" + key + "' appears twice (first on line " +
                            std::to_string(prev->second) + "); expected each key once");
    }
  }
}

void YamlReader::ExpectMap(const std::vector<std::string_view>& allowed) const {
  ExpectMapAnyKeys();
  for (auto it = node_.begin(); it != node_.end(); ++it) {
    const std::string& key = it->first.Scalar();
    bool ok = false;
    for (std::string_view a : allowed) ok = ok || a == key;
    if (!ok) {
      const int key_line = MarkLine(it->first.Mark());
      throw ConfigError(ctx_->file, key_line ? key_line : line_,
                        path_.empty() ? key : path_ + "." + key,
                        "unknown key '" + key + "'; expected one of: " + JoinNames(allowed));
    }
  }
}

void YamlReader::ExpectList() const {
  if (node_.IsNull()) return;  // "key:" with no value = an empty list
  if (!node_.IsSequence()) Fail("expected a list, got " + Describe());
}

bool YamlReader::Has(std::string_view key) const {
  if (!node_.IsMap()) return false;
  for (auto it = node_.begin(); it != node_.end(); ++it)
    if (it->first.IsScalar() && it->first.Scalar() == key) return true;
  return false;
}

YamlReader YamlReader::Child(std::string_view key) const {
  const std::string child_path = path_.empty() ? std::string(key) : path_ + "." + std::string(key);
  if (node_.IsMap()) {
    // first match: ExpectMap() has already rejected duplicate keys
    for (auto it = node_.begin(); it != node_.end(); ++it) {
      if (it->first.IsScalar() && it->first.Scalar() == key) {
        // the key's line: a null value's own mark points past it
        int line = MarkLine(it->first.Mark());
        if (line == 0) line = line_;
        return YamlReader(it->second, child_path, line, ctx_);
      }
    }
  }
  throw ConfigError(ctx_->file, line_, child_path,
                    "required key '" + std::string(key) + "' is missing");
}

YamlReader YamlReader::Element(size_t i) const {
  YAML::Node e = node_[i];
  int line = e.IsNull() ? 0 : MarkLine(e.Mark());
  if (line == 0) line = line_;
  return YamlReader(e, path_ + "[" + std::to_string(i) + "]", line, ctx_);
}

std::vector<std::pair<std::string, YamlReader>> YamlReader::Entries() const {
  ExpectMapAnyKeys();
  std::vector<std::pair<std::string, YamlReader>> out;
  if (node_.IsNull()) return out;
  for (auto it = node_.begin(); it != node_.end(); ++it) {
    const std::string& key = it->first.Scalar();
    out.emplace_back(key, Child(key));
  }
  return out;
}

std::vector<YamlReader> YamlReader::List() const {
  ExpectList();
  std::vector<YamlReader> out;
  if (node_.IsNull()) return out;
  for (size_t i = 0; i < node_.size(); ++i) out.push_back(Element(i));
  return out;
}

double YamlReader::Double() const {
  if (!IsPlainScalar(node_)) Fail("expected a number, got " + Describe());
  std::string_view s = node_.Scalar();
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  double v = 0;
  auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || r.ec != std::errc() || r.ptr != s.data() + s.size()) {
    Fail("expected a number, got " + Describe());
  }
  if (!std::isfinite(v)) Fail("expected a finite number, got " + Describe());
  return v;
}

int YamlReader::Int() const {
  if (!IsPlainScalar(node_)) Fail("expected an integer, got " + Describe());
  std::string_view s = node_.Scalar();
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  long long v = 0;
  auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || r.ec == std::errc::invalid_argument || r.ptr != s.data() + s.size()) {
    Fail("expected an integer, got " + Describe());
  }
  if (r.ec == std::errc::result_out_of_range || v < std::numeric_limits<int>::min() ||
      v > std::numeric_limits<int>::max()) {
    Fail("integer " + node_.Scalar() + " is too large; expected an integer in [" +
         std::to_string(std::numeric_limits<int>::min()) + ", " +
         std::to_string(std::numeric_limits<int>::max()) + "]");
  }
  return static_cast<int>(v);
}

uint64_t YamlReader::Uint64() const {
  const std::string what = "expected a non-negative integer below 2^64, got ";
  if (!IsPlainScalar(node_)) Fail(what + Describe());
  std::string_view s = node_.Scalar();
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  uint64_t v = 0;
  auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || r.ec != std::errc() || r.ptr != s.data() + s.size()) Fail(what + Describe());
  return v;
}

bool YamlReader::Bool() const {
  bool v = false;
  if (!IsPlainScalar(node_) || !YAML::convert<bool>::decode(node_, v)) {
    Fail("expected true or false, got " + Describe());
  }
  return v;
}

std::string YamlReader::String() const {
  if (!node_.IsScalar()) Fail("expected a string, got " + Describe());
  return node_.Scalar();
}

std::string YamlReader::Enum(const std::vector<std::string_view>& valid) const {
  if (!node_.IsScalar()) Fail("expected one of: " + JoinNames(valid) + "; got " + Describe());
  const std::string& s = node_.Scalar();
  for (std::string_view v : valid)
    if (v == s) return s;
  Fail("unknown value '" + s + "'; expected one of: " + JoinNames(valid));
}

Eigen::Vector3d YamlReader::Vector3() const {
  if (!node_.IsSequence() || node_.size() != 3) {
    std::string got = Describe();
    if (node_.IsSequence()) got = "a list of " + std::to_string(node_.size());
    Fail("expected a list of 3 numbers, got " + got);
  }
  Eigen::Vector3d v;
  for (int i = 0; i < 3; ++i) v[i] = Element(i).Double();
  return v;
}

}  // namespace penumbra
