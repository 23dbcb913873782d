#pragma once
// `--backend cpu|cuda|auto` of every verb that renders (run, replay, export, benchmark, bench
// render, contact-sheet, view; docs/gpu.md "Choosing the backend"): one option, registered and
// read here, that overrides the world's `render.backend`. `cuda` on a machine without a usable
// CUDA device is refused before anything runs, with an error naming --backend.
//
//   BackendFlag backend;
//   backend.Add(verb);                 // before parsing
//   backend.Apply(&world.render);      // after parsing: world.render.backend overridden if given

#include <CLI/CLI.hpp>
#include <optional>
#include <string>

#include "penumbra/render/render_settings.h"

namespace penumbra {

/// the --backend option of one verb (see the file comment).
class BackendFlag {
 public:
  /// registers `--backend cpu|cuda|auto` on `verb` (CLI11 refuses other values, exit 2);
  /// `without` says what leaving it out means (for the help text).
  void Add(CLI::App* verb, const std::string& without = "the world's render.backend");
  /// true when the command line gave --backend.
  bool given() const { return !value_.empty(); }
  /// the value as given ("" when not given).
  const std::string& text() const { return value_; }
  /// the backend given, nullopt when not given.
  /// @throws ConfigError("--backend") for `cuda` when ProbeCudaDevice finds no usable device
  ///         (the message says why and what to use instead).
  std::optional<RenderSettings::Backend> Resolve() const;
  /// sets render->backend to the backend given (unchanged when not given).
  /// @throws ConfigError as Resolve.
  void Apply(RenderSettings* render) const;

 private:
  std::string value_;
};

}  // namespace penumbra
