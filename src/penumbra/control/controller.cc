#include "penumbra/control/controller.h"

#include <algorithm>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

// up to `max_names` existing names of `kind` that share the missing name's prefix
// ("robot/"), or any names when none share it, as a hint in the message.
std::string ExistingNamesHint(const ModelInfo& model, ModelObject kind, const std::string& missing,
                              size_t max_names) {
  const std::vector<std::string> all = model.Names(kind);
  const size_t slash = missing.find('/');
  const std::string prefix = slash == std::string::npos ? "" : missing.substr(0, slash + 1);
  std::vector<std::string> picked;
  for (const auto& n : all)
    if (!n.empty() && (prefix.empty() || n.rfind(prefix, 0) == 0)) picked.push_back(n);
  if (picked.empty())
    for (const auto& n : all)
      if (!n.empty()) picked.push_back(n);
  if (picked.empty()) return std::string("the model has no named ") + ModelObjectName(kind) + "s";
  std::string s = std::string("existing ") + ModelObjectName(kind) + " names: ";
  for (size_t i = 0; i < picked.size() && i < max_names; ++i)
    s += (i ? ", '" : "'") + picked[i] + "'";
  if (picked.size() > max_names) s += ", ... (" + std::to_string(picked.size()) + " in all)";
  return s;
}

}  // namespace

std::string Controller::label() const {
  return context_.key.empty() ? type() : type() + " (" + context_.key + ")";
}

void Controller::Initialize(const ModelInfo& model) {
  const std::vector<NameRequirement> reqs = RequiredNames();
  std::vector<int> ids(reqs.size(), -1);
  std::vector<size_t> missing;
  for (size_t i = 0; i < reqs.size(); ++i) {
    ids[i] = model.Find(reqs[i].kind, reqs[i].name);
    if (ids[i] < 0) missing.push_back(i);
  }
  if (!missing.empty()) {
    std::string msg = std::to_string(missing.size()) + " name" + (missing.size() > 1 ? "s" : "") +
                      " not found in the model: ";
    for (size_t k = 0; k < missing.size(); ++k) {
      const NameRequirement& r = reqs[missing[k]];
      if (k) msg += "; ";
      if (!r.key.empty()) msg += r.key + ": ";
      msg += std::string(ModelObjectName(r.kind)) + " '" + r.name + "' (" +
             ExistingNamesHint(model, r.kind, r.name, 8) + ")";
    }
    msg += "; expected names of the robot's MJCF, prefixed with \"<robot>/\"";
    throw ConfigError(context_.file, context_.line, context_.key, msg);
  }
  OnInitialize(model, ids);
}

}  // namespace penumbra
