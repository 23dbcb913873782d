#pragma once
// range checks for controller parameters, with errors that name the world file,
// the line and the key path of the controller block (ControllerContext).

#include <string>

#include "penumbra/control/controller.h"

namespace penumbra {

/// throws ConfigError(context.file, context.line, "<context.key>.<key>", problem).
class ParamCheck {
 public:
  explicit ParamCheck(const ControllerContext& context) : context_(context) {}

  /// @throws ConfigError always.
  [[noreturn]] void Fail(const std::string& key, const std::string& problem) const;
  /// @throws ConfigError unless v is finite and > 0.
  void Positive(const std::string& key, double v) const;
  /// @throws ConfigError unless v is finite and >= 0.
  void NonNegative(const std::string& key, double v) const;

 private:
  const ControllerContext& context_;
};

}  // namespace penumbra
