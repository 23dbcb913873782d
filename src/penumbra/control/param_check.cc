#include "penumbra/control/param_check.h"

#include <cmath>

#include "penumbra/core/error.h"

namespace penumbra {

void ParamCheck::Fail(const std::string& key, const std::string& problem) const {
  throw ConfigError(context_.file, context_.line,
                    context_.key.empty() ? key : context_.key + "." + key, problem);
}

void ParamCheck::Positive(const std::string& key, double v) const {
  if (!(std::isfinite(v) && v > 0))
    Fail(key, "got " + std::to_string(v) + "; expected a number > 0");
}

void ParamCheck::NonNegative(const std::string& key, double v) const {
  if (!(std::isfinite(v) && v >= 0))
    Fail(key, "got " + std::to_string(v) + "; expected a number >= 0");
}

}  // namespace penumbra
