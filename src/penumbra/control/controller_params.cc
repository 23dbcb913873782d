#include "penumbra/control/controller_params.h"

#include <cmath>

#include "penumbra/config/config_value.h"
#include "penumbra/control/param_limits.h"
#include "penumbra/control/param_mapping.h"
#include "penumbra/core/error.h"

namespace penumbra {

struct ControllerParams::Impl {
  ConfigValue root;
  ParamMapping keys;
};

using param::Repr;

ControllerParams::ControllerParams(const ConfigValue& params, ControllerContext context)
    : context_(std::move(context)), impl_(std::make_unique<Impl>()) {
  impl_->root = params;
  // an empty block (or none set in code): no parameters
  if (!impl_->root.IsDefined() || impl_->root.IsNull()) return;
  if (!impl_->root.IsMap()) {
    throw ConfigError(context_.file, context_.line, context_.key,
                      "got " + Repr(impl_->root) + "; expected a mapping of controller parameters");
  }
  impl_->keys.MarkKnown("type");
  impl_->keys.Load(impl_->root);
}

ControllerParams::~ControllerParams() = default;

void ControllerParams::Fail(const std::string& key, const std::string& problem) const {
  throw ConfigError(context_.file, context_.line,
                    context_.key.empty() ? key : context_.key + "." + key, problem);
}

bool ControllerParams::Has(const std::string& key) const { return impl_->keys.Has(key); }

const ConfigValue* ControllerParams::Get(const std::string& key) { return impl_->keys.Get(key); }

std::string ControllerParams::String(const std::string& key) {
  const ConfigValue* n = Get(key);
  if (const auto problem = param::NameProblem(n)) Fail(key, *problem);
  return n->Scalar();
}

double ControllerParams::Number(const std::string& key, std::optional<double> fallback, double min,
                                double max, bool min_exclusive) {
  std::string problem;
  const double v = param::ReadNumber(Get(key), fallback, min, max, min_exclusive,
                                     param::RangeText(min, max, min_exclusive), &problem);
  if (!problem.empty()) Fail(key, problem);
  return v;
}

bool ControllerParams::Bool(const std::string& key, bool fallback) {
  const ConfigValue* n = Get(key);
  if (!n) return fallback;
  bool v = false;
  if (n->ToBoolLoose(&v)) return v;
  Fail(key, "got " + Repr(*n) + "; expected true or false");
}

std::vector<Eigen::Vector2d> ControllerParams::Points2(const std::string& key, size_t min_count) {
  const ConfigValue* n = Get(key);
  const std::string bound = param::FormatNumber(kMaxParamPositionM);
  const std::string expected = "expected a list of at least " + std::to_string(min_count) +
                               " [x, y] pairs of numbers (m) in [-" + bound + ", " + bound +
                               "], e.g. [[1.0, 0.0], [1.0, 1.0]]";
  if (!n) Fail(key, "missing; " + expected);
  if (!n->IsSequence()) Fail(key, "got " + Repr(*n) + "; " + expected);
  std::vector<Eigen::Vector2d> pts;
  for (size_t i = 0; i < n->size(); ++i) {
    const ConfigValue p = (*n)[i];
    const std::string item_key = key + "[" + std::to_string(i) + "]";
    if (!p.IsSequence() || p.size() != 2) Fail(item_key, "got " + Repr(p) + "; expected [x, y]");
    Eigen::Vector2d v;
    for (int k = 0; k < 2; ++k) {
      if (!param::ToNumber(p[k], &v[k]) || std::abs(v[k]) > kMaxParamPositionM)
        Fail(item_key, "got " + Repr(p[k]) + " as coordinate " + std::to_string(k) +
                           "; expected a number (m) in [-" + bound + ", " + bound + "]");
    }
    pts.push_back(v);
  }
  if (pts.size() < min_count)
    Fail(key, "got " + std::to_string(pts.size()) + " points; " + expected);
  return pts;
}

void ControllerParams::CheckNoUnknownKeys() const {
  if (const auto unknown = impl_->keys.UnknownKeys()) Fail(unknown->first, unknown->second);
}

std::string DescribeParamNode(const ConfigValue& n) {
  if (n.IsScalar()) return "'" + n.Scalar() + "'";
  if (n.IsSequence()) return "a list of " + std::to_string(n.size()) + " items";
  if (n.IsMap()) return "a mapping";
  return "nothing";
}

double ParamNumberAt(ControllerParams& p, const ConfigValue& n, const std::string& key,
                     const std::string& expected) {
  double v = 0;
  const bool ok = n.ToDoubleLoose(&v);
  if (!ok || !std::isfinite(v))
    p.Fail(key, "got " + DescribeParamNode(n) + "; expected " + expected);
  return v;
}

double ParamNumberAt(ControllerParams& p, const ConfigValue& n, const std::string& key, double min,
                     double max, const std::string& unit) {
  const std::string range = "in [" + param::FormatNumber(min) + ", " + param::FormatNumber(max) +
                            "]" + (unit.empty() ? "" : " (" + unit + ")");
  const double v = ParamNumberAt(p, n, key, "a number " + range);
  if (v < min || v > max)
    p.Fail(key, "got " + param::FormatNumber(v) + "; expected a number " + range);
  return v;
}

std::vector<double> ParamNumbersAt(ControllerParams& p, const ConfigValue& n,
                                   const std::string& key, const std::string& expected,
                                   bool (*ok)(double)) {
  std::vector<double> out;
  if (n.IsSequence()) {
    if (n.size() == 0) p.Fail(key, "got an empty list; expected " + expected);
    for (size_t i = 0; i < n.size(); ++i) {
      const std::string k = key + "[" + std::to_string(i) + "]";
      const double v = ParamNumberAt(p, n[i], k, expected);
      if (!ok(v)) p.Fail(k, "got " + n[i].Scalar() + "; expected " + expected);
      out.push_back(v);
    }
    return out;
  }
  const double v = ParamNumberAt(p, n, key, expected + " (or a list of them)");
  if (!ok(v)) p.Fail(key, "got " + n.Scalar() + "; expected " + expected);
  return {v};
}

}  // namespace penumbra
