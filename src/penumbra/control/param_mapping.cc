#include "penumbra/control/param_mapping.h"

#include <cmath>
#include <sstream>

namespace penumbra {

void ParamMapping::Load(const ConfigValue& node) {
  for (const ConfigEntry& e : node.entries()) entries_.emplace_back(e.key, ConfigValue(e.value));
}

bool ParamMapping::Has(const std::string& key) const {
  for (const auto& e : entries_)
    if (e.first == key) return true;
  return false;
}

const ConfigValue* ParamMapping::Get(const std::string& key) {
  known_.insert(key);
  for (const auto& e : entries_)
    if (e.first == key) return &e.second;
  return nullptr;
}

std::optional<std::pair<std::string, std::string>> ParamMapping::UnknownKeys() const {
  std::string first, unknown;
  for (const auto& e : entries_) {
    if (known_.count(e.first)) continue;
    if (first.empty()) first = e.first;
    unknown += (unknown.empty() ? "'" : ", '") + e.first + "'";
  }
  if (unknown.empty()) return std::nullopt;
  std::string allowed;
  for (const auto& k : known_) allowed += (allowed.empty() ? "" : ", ") + k;
  return std::make_pair(first, "unknown key(s) " + unknown + "; expected only: " + allowed);
}

namespace param {

std::string Repr(const ConfigValue& n) {
  if (n.IsScalar()) return "'" + n.Scalar() + "'";
  if (n.IsSequence())
    return "a list of " + std::to_string(n.size()) + (n.size() == 1 ? " item" : " items");
  if (n.IsMap()) return "a mapping";
  return "nothing";
}

std::string FormatNumber(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

std::string RangeText(double min, double max, bool min_exclusive) {
  std::string s = (min_exclusive ? "> " : ">= ") + FormatNumber(min);
  if (!std::isinf(max)) s += " and <= " + FormatNumber(max);
  return s;
}

bool ToNumber(const ConfigValue& n, double* v) { return n.ToDoubleLoose(v) && std::isfinite(*v); }

std::optional<std::string> NameProblem(const ConfigValue* n) {
  if (!n) return "missing; expected a name";
  if (!n->IsScalar() || n->Scalar().empty()) return "got " + Repr(*n) + "; expected a name";
  return std::nullopt;
}

double ReadNumber(const ConfigValue* n, std::optional<double> fallback, double min, double max,
                  bool min_exclusive, const std::string& range, std::string* problem) {
  if (!n) {
    if (fallback) return *fallback;
    *problem = "missing; expected a number " + range;
    return 0;
  }
  double v = 0;
  if (!ToNumber(*n, &v)) {
    *problem = "got " + Repr(*n) + "; expected a number " + range;
    return 0;
  }
  if (v < min || (min_exclusive && v == min) || v > max) {
    *problem = "got " + FormatNumber(v) + "; expected a number " + range;
    return 0;
  }
  return v;
}

}  // namespace param
}  // namespace penumbra
