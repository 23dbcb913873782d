#include "penumbra/config/config_value.h"

#include <charconv>
#include <cmath>
#include <limits>

namespace penumbra {

namespace {

const std::string& EmptyConfigText() {
  static const std::string kEmpty;
  return kEmpty;
}

const std::vector<ConfigEntry>& EmptyConfigEntries() {
  static const std::vector<ConfigEntry> kEmpty;
  return kEmpty;
}

// from_chars over the whole text, a leading '+' allowed
bool ParseConfigDouble(std::string_view s, double* v) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  if (s.empty()) return false;
  double x = 0;
  auto r = std::from_chars(s.data(), s.data() + s.size(), x);
  if (r.ec != std::errc() || r.ptr != s.data() + s.size()) return false;
  *v = x;
  return true;
}

// yaml-cpp's convert<bool>: each name in lower case, UPPER case or Capitalised
bool ParseConfigBool(const std::string& s, bool* v) {
  static const struct {
    const char* t;
    const char* f;
  } kNames[] = {{"y", "n"}, {"yes", "no"}, {"true", "false"}, {"on", "off"}};
  auto matches = [&s](const std::string& name) {
    if (s == name) return true;
    std::string upper = name, cap = name;
    for (char& c : upper) c = static_cast<char>(c - 'a' + 'A');
    cap[0] = upper[0];
    return s == upper || s == cap;
  };
  for (const auto& n : kNames) {
    if (matches(n.t)) {
      *v = true;
      return true;
    }
    if (matches(n.f)) {
      *v = false;
      return true;
    }
  }
  return false;
}

}  // namespace

ConfigValue ConfigValue::Null(int line) {
  auto n = std::make_shared<ConfigNode>();
  n->kind = ConfigKind::kNull;
  n->line = line;
  return ConfigValue(std::move(n));
}

ConfigValue ConfigValue::Scalar(std::string text, int line) {
  auto n = std::make_shared<ConfigNode>();
  n->kind = ConfigKind::kScalar;
  n->scalar = std::move(text);
  n->line = line;
  return ConfigValue(std::move(n));
}

ConfigValue ConfigValue::Map(int line) {
  auto n = std::make_shared<ConfigNode>();
  n->kind = ConfigKind::kMap;
  n->line = line;
  return ConfigValue(std::move(n));
}

const std::string& ConfigValue::Scalar() const {
  return IsScalar() ? node_->scalar : EmptyConfigText();
}

size_t ConfigValue::size() const {
  if (IsSequence()) return node_->items.size();
  if (IsMap()) return node_->entries.size();
  return 0;
}

ConfigValue ConfigValue::operator[](size_t i) const {
  if (!IsSequence() || i >= node_->items.size()) return ConfigValue();
  return ConfigValue(node_->items[i]);
}

ConfigValue ConfigValue::operator[](std::string_view key) const {
  if (!IsMap()) return ConfigValue();
  for (const ConfigEntry& e : node_->entries)
    if (e.key_is_scalar && e.key == key) return ConfigValue(e.value);
  return ConfigValue();
}

const std::vector<ConfigEntry>& ConfigValue::entries() const {
  return IsMap() ? node_->entries : EmptyConfigEntries();
}

std::vector<std::pair<ConfigValue, ConfigValue>> ConfigValue::pairs() const {
  std::vector<std::pair<ConfigValue, ConfigValue>> out;
  for (const ConfigEntry& e : entries()) {
    ConfigValue key = e.key_is_scalar ? Scalar(e.key, e.key_line) : Null(e.key_line);
    out.emplace_back(std::move(key), ConfigValue(e.value));
  }
  return out;
}

bool ConfigValue::ToDouble(double* v) const {
  return IsScalar() && !node_->quoted && ParseConfigDouble(node_->scalar, v);
}

bool ConfigValue::ToDoubleLoose(double* v) const {
  if (!IsScalar()) return false;
  const std::string& s = node_->scalar;
  if (ParseConfigDouble(s, v)) return true;
  // yaml-cpp's names of the special values
  if (s == ".inf" || s == ".Inf" || s == ".INF" || s == "+.inf" || s == "+.Inf" || s == "+.INF") {
    *v = std::numeric_limits<double>::infinity();
    return true;
  }
  if (s == "-.inf" || s == "-.Inf" || s == "-.INF") {
    *v = -std::numeric_limits<double>::infinity();
    return true;
  }
  if (s == ".nan" || s == ".NaN" || s == ".NAN") {
    *v = std::numeric_limits<double>::quiet_NaN();
    return true;
  }
  return false;
}

bool ConfigValue::ToBool(bool* v) const {
  return IsScalar() && !node_->quoted && ParseConfigBool(node_->scalar, v);
}

bool ConfigValue::ToBoolLoose(bool* v) const {
  return IsScalar() && ParseConfigBool(node_->scalar, v);
}

std::string ConfigValue::Describe() const {
  switch (kind()) {
    case ConfigKind::kUndefined:
    case ConfigKind::kNull:
      return "nothing";
    case ConfigKind::kScalar:
      if (node_->quoted) return "the quoted string \"" + node_->scalar + "\"";
      return "'" + node_->scalar + "'";
    case ConfigKind::kList:
      return "a list";
    case ConfigKind::kMap:
      return "a mapping";
  }
  return "?";
}

ConfigValue WithEntry(const ConfigValue& base, const std::string& key, const ConfigValue& value) {
  auto n = std::make_shared<ConfigNode>();
  n->kind = ConfigKind::kMap;
  n->line = base.line();
  bool replaced = false;
  for (const ConfigEntry& e : base.entries()) {
    n->entries.push_back(e);
    if (e.key_is_scalar && e.key == key && !replaced) {
      n->entries.back().value = value.node() ? value.node() : ConfigValue::Null().node();
      replaced = true;
    }
  }
  if (!replaced) {
    ConfigEntry e;
    e.key = key;
    e.key_line = value.line();
    e.value = value.node() ? value.node() : ConfigValue::Null().node();
    n->entries.push_back(std::move(e));
  }
  return ConfigValue(std::move(n));
}

ConfigValue WithoutEntry(const ConfigValue& base, std::string_view key) {
  auto n = std::make_shared<ConfigNode>();
  n->kind = ConfigKind::kMap;
  n->line = base.line();
  for (const ConfigEntry& e : base.entries())
    if (!(e.key_is_scalar && e.key == key)) n->entries.push_back(e);
  return ConfigValue(std::move(n));
}

}  // namespace penumbra
