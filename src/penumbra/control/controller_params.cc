#include "penumbra/control/controller_params.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <sstream>

#include "penumbra/core/error.h"

namespace penumbra {

struct ControllerParams::Impl {
  YAML::Node root;
  std::vector<std::pair<std::string, YAML::Node>> entries;  // in file order
};

namespace {

std::string Repr(const YAML::Node& n) {
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

}  // namespace

ControllerParams::ControllerParams(const std::string& params_yaml, ControllerContext context)
    : context_(std::move(context)), impl_(std::make_unique<Impl>()) {
  try {
    impl_->root = YAML::Load(params_yaml);
  } catch (const YAML::Exception& e) {
    throw ConfigError(context_.file, context_.line, context_.key,
                      std::string("invalid YAML in the controller block: ") + e.what());
  }
  if (impl_->root.IsNull()) return;  // an empty block: no parameters
  if (!impl_->root.IsMap()) {
    throw ConfigError(context_.file, context_.line, context_.key,
                      "got " + Repr(impl_->root) + "; expected a mapping of controller parameters");
  }
  known_.insert("type");
  for (const auto& kv : impl_->root) impl_->entries.emplace_back(kv.first.Scalar(), kv.second);
}

ControllerParams::~ControllerParams() = default;

void ControllerParams::Fail(const std::string& key, const std::string& problem) const {
  throw ConfigError(context_.file, context_.line,
                    context_.key.empty() ? key : context_.key + "." + key, problem);
}

bool ControllerParams::Has(const std::string& key) const {
  for (const auto& e : impl_->entries)
    if (e.first == key) return true;
  return false;
}

const YAML::Node* ControllerParams::Get(const std::string& key) {
  known_.insert(key);
  for (const auto& e : impl_->entries)
    if (e.first == key) return &e.second;
  return nullptr;
}

std::string ControllerParams::String(const std::string& key) {
  const YAML::Node* n = Get(key);
  if (!n) Fail(key, "missing; expected a name");
  if (!n->IsScalar() || n->Scalar().empty()) Fail(key, "got " + Repr(*n) + "; expected a name");
  return n->Scalar();
}

double ControllerParams::Number(const std::string& key, std::optional<double> fallback, double min,
                                double max, bool min_exclusive) {
  const std::string range = std::string(min_exclusive ? "> " : ">= ") + FormatNumber(min) +
                            (std::isinf(max) ? "" : " and <= " + FormatNumber(max));
  const YAML::Node* n = Get(key);
  if (!n) {
    if (fallback) return *fallback;
    Fail(key, "missing; expected a number " + range);
  }
  double v = 0;
  bool ok = n->IsScalar();
  if (ok) {
    try {
      v = n->as<double>();
    } catch (const YAML::Exception&) {
      ok = false;
    }
  }
  if (!ok || !std::isfinite(v)) Fail(key, "got " + Repr(*n) + "; expected a number " + range);
  if (v < min || (min_exclusive && v == min) || v > max)
    Fail(key, "got " + FormatNumber(v) + "; expected a number " + range);
  return v;
}

bool ControllerParams::Bool(const std::string& key, bool fallback) {
  const YAML::Node* n = Get(key);
  if (!n) return fallback;
  if (n->IsScalar()) {
    try {
      return n->as<bool>();
    } catch (const YAML::Exception&) {
    }
  }
  Fail(key, "got " + Repr(*n) + "; expected true or false");
}

std::vector<Eigen::Vector2d> ControllerParams::Points2(const std::string& key, size_t min_count) {
  const YAML::Node* n = Get(key);
  const std::string expected = "expected a list of at least " + std::to_string(min_count) +
                               " [x, y] pairs of numbers (m), e.g. [[1.0, 0.0], [1.0, 1.0]]";
  if (!n) Fail(key, "missing; " + expected);
  if (!n->IsSequence()) Fail(key, "got " + Repr(*n) + "; " + expected);
  std::vector<Eigen::Vector2d> pts;
  for (size_t i = 0; i < n->size(); ++i) {
    const YAML::Node p = (*n)[i];
    const std::string item_key = key + "[" + std::to_string(i) + "]";
    if (!p.IsSequence() || p.size() != 2) Fail(item_key, "got " + Repr(p) + "; expected [x, y]");
    Eigen::Vector2d v;
    for (int k = 0; k < 2; ++k) {
      bool ok = p[k].IsScalar();
      if (ok) {
        try {
          v[k] = p[k].as<double>();
        } catch (const YAML::Exception&) {
          ok = false;
        }
      }
      if (!ok || !std::isfinite(v[k]))
        Fail(item_key, "got " + Repr(p[k]) + " as coordinate " + std::to_string(k) +
                           "; expected a finite number (m)");
    }
    pts.push_back(v);
  }
  if (pts.size() < min_count)
    Fail(key, "got " + std::to_string(pts.size()) + " points; " + expected);
  return pts;
}

void ControllerParams::CheckNoUnknownKeys() const {
  std::string first, unknown;
  for (const auto& e : impl_->entries) {
    if (known_.count(e.first)) continue;
    if (first.empty()) first = e.first;
    unknown += (unknown.empty() ? "'" : ", '") + e.first + "'";
  }
  if (unknown.empty()) return;
  std::string allowed;
  for (const auto& k : known_) allowed += (allowed.empty() ? "" : ", ") + k;
  Fail(first, "unknown key(s) " + unknown + "; expected only: " + allowed);
}

}  // namespace penumbra
