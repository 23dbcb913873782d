#pragma once
// `penumbra eval ate|rpe GROUND_TRUTH ESTIMATE [options]`: trajectory metrics of an estimate
// against ground truth, both TUM-format files (eval/, docs/evaluation.md). the report goes to
// stdout as text (or JSON with --format json); --json FILE and --plot FILE.png write files.

#include <memory>
#include <string>

#include "penumbra/app/command.h"

namespace penumbra {

/// the `eval` verb (app/command.h): `eval ate` and `eval rpe`.
class EvalCommand : public Command {
 public:
  EvalCommand();
  ~EvalCommand() override;
  EvalCommand(const EvalCommand&) = delete;
  EvalCommand& operator=(const EvalCommand&) = delete;

  std::string name() const override;
  std::string summary() const override;
  /// adds `ate` and `rpe` with their options to `eval`.
  void AddOptions(CLI::App* eval) override;
  /// reads both files, evaluates, writes the report to stdout and the --json / --plot files.
  /// returns the exit code (0).
  /// @throws ConfigError for an unreadable or malformed input file, too few associated poses,
  ///         or (rpe) no pose pair at the requested delta: bad input, exit code 2 in RunCli;
  ///         Error when an output file cannot be written (exit code 1).
  int Run(const CommandArgs& args) override;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace penumbra
