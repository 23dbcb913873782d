#include "penumbra/control/param_node.h"

#include <cmath>

#include "penumbra/config/config_value.h"
#include "penumbra/control/param_mapping.h"
#include "penumbra/core/error.h"

namespace penumbra {

struct ParamNode::Impl {
  ConfigValue node;
  ParamMapping keys;
};

namespace {

using param::Repr;
using param::ToNumber;

// as param::RangeText, but "finite" when both bounds are infinite
std::string RangeText(double min, double max, bool min_exclusive) {
  if (std::isinf(min) && std::isinf(max)) return "finite";
  return param::RangeText(min, max, min_exclusive);
}

[[noreturn]] void FailAt(const ControllerContext& c, const std::string& key,
                         const std::string& problem) {
  throw ConfigError(c.file, c.line, c.key.empty() ? key : c.key + "." + key, problem);
}

}  // namespace

ParamNode::ParamNode(const ConfigValue& node, std::string path, ControllerContext context)
    : impl_(std::make_unique<Impl>()), path_(std::move(path)), context_(std::move(context)) {
  impl_->node = node;
  impl_->keys.Load(node);
}

ParamNode::~ParamNode() = default;
ParamNode::ParamNode(ParamNode&&) noexcept = default;

std::string ParamNode::KeyPath(const std::string& key) const {
  return path_.empty() ? key : path_ + "." + key;
}

void ParamNode::Fail(const std::string& key, const std::string& problem) const {
  FailAt(context_, KeyPath(key), problem);
}

void ParamNode::FailHere(const std::string& problem) const { FailAt(context_, path_, problem); }

bool ParamNode::Has(const std::string& key) const { return impl_->keys.Has(key); }

const ConfigValue* ParamNode::Get(const std::string& key) {
  if (!impl_->node.IsMap()) FailHere("got " + Repr(impl_->node) + "; expected a mapping");
  return impl_->keys.Get(key);
}

const ConfigValue* ParamNode::Raw(const std::string& key) { return Get(key); }

double ParamNode::Number(const std::string& key, std::optional<double> fallback, double min,
                         double max) {
  const ConfigValue* n = Get(key);
  std::string problem;
  const double v =
      param::ReadNumber(n, fallback, min, max, false, RangeText(min, max, false), &problem);
  if (!problem.empty()) Fail(key, problem);
  return v;
}

std::vector<double> ParamNode::Numbers(const std::string& key, size_t count, double min, double max,
                                       const std::string& unit) {
  const ConfigValue* n = Get(key);
  const std::string expected =
      "expected a list of " + std::to_string(count) + " numbers" +
      (unit.empty() ? "" : " (" + unit + ")") +
      (std::isinf(min) && std::isinf(max) ? "" : ", each " + RangeText(min, max, false));
  if (!n) Fail(key, "missing; " + expected);
  if (!n->IsSequence() || n->size() != count) Fail(key, "got " + Repr(*n) + "; " + expected);
  std::vector<double> out(count);
  for (size_t i = 0; i < count; ++i) {
    if (!ToNumber((*n)[i], &out[i]) || out[i] < min || out[i] > max)
      Fail(key + "[" + std::to_string(i) + "]", "got " + Repr((*n)[i]) + "; " + expected);
  }
  return out;
}

std::string ParamNode::String(const std::string& key) {
  const ConfigValue* n = Get(key);
  if (const auto problem = param::NameProblem(n)) Fail(key, *problem);
  return n->Scalar();
}

ParamNode ParamNode::Child(const std::string& key) {
  const ConfigValue* n = Get(key);
  if (!n) Fail(key, "missing; expected a mapping");
  if (!n->IsMap()) Fail(key, "got " + Repr(*n) + "; expected a mapping");
  return ParamNode(*n, KeyPath(key), context_);
}

void ParamNode::CheckNoUnknownKeys() const {
  if (const auto unknown = impl_->keys.UnknownKeys()) Fail(unknown->first, unknown->second);
}

std::vector<std::string> ReadNameList(ControllerParams& params, const std::string& key,
                                      size_t min_count, const std::string& prefix) {
  const ConfigValue* n = params.Raw(key);
  const std::string expected =
      "expected a list of at least " + std::to_string(min_count) + " names, e.g. [joint1, joint2]";
  if (!n) params.Fail(key, "missing; " + expected);
  if (!n->IsSequence()) params.Fail(key, "got " + Repr(*n) + "; " + expected);
  std::vector<std::string> out;
  for (size_t i = 0; i < n->size(); ++i) {
    const ConfigValue item = (*n)[i];
    const std::string item_key = key + "[" + std::to_string(i) + "]";
    if (!item.IsScalar() || item.Scalar().empty())
      params.Fail(item_key, "got " + Repr(item) + "; expected a name");
    const std::string name = prefix + item.Scalar();
    for (size_t k = 0; k < out.size(); ++k)
      if (out[k] == name)
        params.Fail(item_key, "'" + item.Scalar() + "' is listed twice (also at " + key + "[" +
                                  std::to_string(k) + "]); expected distinct names");
    out.push_back(name);
  }
  if (out.size() < min_count)
    params.Fail(key, "got " + std::to_string(out.size()) + " names; " + expected);
  return out;
}

std::vector<double> ReadPerJoint(ControllerParams& params, const std::string& key, size_t count,
                                 std::optional<std::vector<double>> fallback, double min,
                                 double max, bool min_exclusive) {
  const std::string range = RangeText(min, max, min_exclusive);
  const std::string expected = "expected a number " + range + " or a list of " +
                               std::to_string(count) + " such numbers (one per joint)";
  const ConfigValue* n = params.Raw(key);
  if (!n) {
    if (fallback) return *fallback;
    params.Fail(key, "missing; " + expected);
  }
  auto check = [&](const ConfigValue& item, const std::string& item_key) {
    double v = 0;
    if (!ToNumber(item, &v) || v < min || v > max || (min_exclusive && v == min))
      params.Fail(item_key, "got " + Repr(item) + "; " + expected);
    return v;
  };
  if (n->IsScalar()) return std::vector<double>(count, check(*n, key));
  if (!n->IsSequence() || n->size() != count) params.Fail(key, "got " + Repr(*n) + "; " + expected);
  std::vector<double> out(count);
  for (size_t i = 0; i < count; ++i) out[i] = check((*n)[i], key + "[" + std::to_string(i) + "]");
  return out;
}

std::optional<std::vector<double>> ReadOptionalNumbers(ControllerParams& params,
                                                       const std::string& key, size_t count,
                                                       double min, double max,
                                                       const std::string& unit) {
  const ConfigValue* n = params.Raw(key);
  if (!n) return std::nullopt;
  const std::string expected =
      "expected a list of " + std::to_string(count) + " numbers" +
      (unit.empty() ? "" : " (" + unit + ")") +
      (std::isinf(min) && std::isinf(max) ? "" : ", each " + RangeText(min, max, false));
  if (!n->IsSequence() || n->size() != count) params.Fail(key, "got " + Repr(*n) + "; " + expected);
  std::vector<double> out(count);
  for (size_t i = 0; i < count; ++i)
    if (!ToNumber((*n)[i], &out[i]) || out[i] < min || out[i] > max)
      params.Fail(key + "[" + std::to_string(i) + "]", "got " + Repr((*n)[i]) + "; " + expected);
  return out;
}

}  // namespace penumbra
