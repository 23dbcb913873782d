#include "penumbra/config/param_reader.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>

#include "penumbra/core/error.h"

namespace penumbra {

struct ParamReader::Context {
  std::string file;
  LineTable* lines = nullptr;
  // the keys asked for of each mapping node, in the order they were first asked
  std::map<const ConfigNode*, std::vector<std::string>> asked;
};

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

ParamReader::ParamReader(const ConfigValue& root, std::string file, LineTable* lines)
    : node_(root), path_(), line_(root.line()) {
  auto ctx = std::make_shared<Context>();
  ctx->file = std::move(file);
  ctx->lines = lines;
  ctx_ = std::move(ctx);
  if (line_ == 0) line_ = 1;
  if (ctx_->lines) ctx_->lines->Record(path_, line_);
}

ParamReader::ParamReader(ConfigValue node, std::string path, int line, std::shared_ptr<Context> ctx)
    : node_(std::move(node)), path_(std::move(path)), line_(line), ctx_(std::move(ctx)) {
  if (ctx_->lines) ctx_->lines->Record(path_, line_);
}

const std::string& ParamReader::file() const { return ctx_->file; }

void ParamReader::Fail(const std::string& problem) const {
  throw ConfigError(ctx_->file, line_, path_, problem);
}

void ParamReader::MarkAsked(std::string_view key) const {
  if (!node_.IsMap()) return;
  std::vector<std::string>& keys = ctx_->asked[node_.node().get()];
  if (std::find(keys.begin(), keys.end(), key) == keys.end()) keys.emplace_back(key);
}

void ParamReader::ExpectMapAnyKeys() const {
  if (node_.IsNull()) return;  // "key:" with no value = an empty mapping
  if (!node_.IsMap()) Fail("expected a mapping (key: value pairs), got " + Describe());
  std::map<std::string, int> seen;
  for (const ConfigEntry& e : node_.entries()) {
    if (!e.key_is_scalar) {
      throw ConfigError(ctx_->file, e.key_line ? e.key_line : line_, path_,
                        "expected a key name, got a list or mapping as a key");
    }
    auto [prev, inserted] = seen.emplace(e.key, e.key_line);
    if (!inserted) {
      throw ConfigError(ctx_->file, e.key_line ? e.key_line : line_,
                        path_.empty() ? e.key : path_ + "." + e.key,
                        "key '" + e.key + "' appears twice (first on line " +
                            std::to_string(prev->second) + "); expected each key once");
    }
  }
}

void ParamReader::ExpectMap(const std::vector<std::string_view>& allowed) const {
  ExpectMapAnyKeys();
  for (const ConfigEntry& e : node_.entries()) {
    bool ok = false;
    for (std::string_view a : allowed) ok = ok || a == e.key;
    if (!ok) {
      throw ConfigError(ctx_->file, e.key_line ? e.key_line : line_,
                        path_.empty() ? e.key : path_ + "." + e.key,
                        "unknown key '" + e.key + "'; expected one of: " + JoinNames(allowed));
    }
  }
}

void ParamReader::ReportUnused() const {
  ExpectMapAnyKeys();
  if (!node_.IsMap()) return;
  const auto it = ctx_->asked.find(node_.node().get());
  static const std::vector<std::string> kNone;
  const std::vector<std::string>& asked = it == ctx_->asked.end() ? kNone : it->second;
  for (const ConfigEntry& e : node_.entries()) {
    if (std::find(asked.begin(), asked.end(), e.key) != asked.end()) continue;
    std::vector<std::string_view> names(asked.begin(), asked.end());
    throw ConfigError(ctx_->file, e.key_line ? e.key_line : line_,
                      path_.empty() ? e.key : path_ + "." + e.key,
                      "unknown key '" + e.key + "'; expected one of: " + JoinNames(names));
  }
}

void ParamReader::ExpectList() const {
  if (node_.IsNull()) return;  // "key:" with no value = an empty list
  if (!node_.IsSequence()) Fail("expected a list, got " + Describe());
}

bool ParamReader::Has(std::string_view key) const {
  MarkAsked(key);
  return node_.IsMap() && node_[key].IsDefined();
}

std::optional<ParamReader> ParamReader::Find(std::string_view key) const {
  if (!Has(key)) return std::nullopt;
  return Child(key);
}

ParamReader ParamReader::Child(std::string_view key) const {
  MarkAsked(key);
  const std::string child_path = path_.empty() ? std::string(key) : path_ + "." + std::string(key);
  // first match: ExpectMap() has already rejected duplicate keys
  for (const ConfigEntry& e : node_.entries()) {
    if (e.key_is_scalar && e.key == key) {
      // the key's line: a null value's own mark points past it
      const int line = e.key_line ? e.key_line : line_;
      return ParamReader(ConfigValue(e.value), child_path, line, ctx_);
    }
  }
  throw ConfigError(ctx_->file, line_, child_path,
                    "required key '" + std::string(key) + "' is missing");
}

ParamReader ParamReader::Element(size_t i) const {
  ConfigValue e = node_[i];
  int line = e.IsNull() ? 0 : e.line();
  if (line == 0) line = line_;
  return ParamReader(e, path_ + "[" + std::to_string(i) + "]", line, ctx_);
}

std::vector<std::pair<std::string, ParamReader>> ParamReader::Entries() const {
  ExpectMapAnyKeys();
  std::vector<std::pair<std::string, ParamReader>> out;
  for (const ConfigEntry& e : node_.entries()) out.emplace_back(e.key, Child(e.key));
  return out;
}

std::vector<ParamReader> ParamReader::List() const {
  ExpectList();
  std::vector<ParamReader> out;
  for (size_t i = 0; i < node_.size() && node_.IsSequence(); ++i) out.push_back(Element(i));
  return out;
}

double ParamReader::Double() const {
  double v = 0;
  if (!node_.ToDouble(&v)) Fail("expected a number, got " + Describe());
  if (!std::isfinite(v)) Fail("expected a finite number, got " + Describe());
  return v;
}

double ParamReader::Double(double min, double max, std::string_view unit) const {
  const double v = Double();
  if (v < min || v > max) {
    std::string range;
    if (std::isinf(min)) {
      range = "<= " + FormatNumber(max);
    } else if (std::isinf(max)) {
      range = ">= " + FormatNumber(min);
    } else {
      range = "in [" + FormatNumber(min) + ", " + FormatNumber(max) + "]";
    }
    Fail("got " + FormatNumber(v) + "; expected a number " + range +
         (unit.empty() ? "" : " (" + std::string(unit) + ")"));
  }
  return v;
}

int ParamReader::Int() const {
  if (!node_.IsScalar() || node_.IsQuoted()) Fail("expected an integer, got " + Describe());
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

int ParamReader::Int(int min, int max) const {
  const int v = Int();
  if (v < min || v > max) {
    Fail("got " + std::to_string(v) + "; expected an integer in [" + std::to_string(min) + ", " +
         std::to_string(max) + "]");
  }
  return v;
}

uint64_t ParamReader::Uint64() const {
  const std::string what = "expected a non-negative integer below 2^64, got ";
  if (!node_.IsScalar() || node_.IsQuoted()) Fail(what + Describe());
  std::string_view s = node_.Scalar();
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  uint64_t v = 0;
  auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || r.ec != std::errc() || r.ptr != s.data() + s.size()) Fail(what + Describe());
  return v;
}

bool ParamReader::Bool() const {
  bool v = false;
  if (!node_.ToBool(&v)) Fail("expected true or false, got " + Describe());
  return v;
}

std::string ParamReader::String() const {
  if (!node_.IsScalar()) Fail("expected a string, got " + Describe());
  return node_.Scalar();
}

std::string ParamReader::Enum(const std::vector<std::string_view>& valid) const {
  if (!node_.IsScalar()) Fail("expected one of: " + JoinNames(valid) + "; got " + Describe());
  const std::string& s = node_.Scalar();
  for (std::string_view v : valid)
    if (v == s) return s;
  Fail("unknown value '" + s + "'; expected one of: " + JoinNames(valid));
}

Eigen::Vector3d ParamReader::Vector3() const {
  if (!node_.IsSequence() || node_.size() != 3) {
    std::string got = Describe();
    if (node_.IsSequence()) got = "a list of " + std::to_string(node_.size());
    Fail("expected a list of 3 numbers, got " + got);
  }
  Eigen::Vector3d v;
  for (int i = 0; i < 3; ++i) v[i] = Element(i).Double();
  return v;
}

std::vector<double> ParamReader::Doubles(size_t count) const {
  if (!node_.IsSequence() || (count != 0 && node_.size() != count)) {
    std::string got = Describe();
    if (node_.IsSequence()) got = "a list of " + std::to_string(node_.size());
    Fail("expected a list of " + (count ? std::to_string(count) + " " : std::string()) +
         "numbers, got " + got);
  }
  std::vector<double> out;
  out.reserve(node_.size());
  for (size_t i = 0; i < node_.size(); ++i) out.push_back(Element(i).Double());
  return out;
}

}  // namespace penumbra
