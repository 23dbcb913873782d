#pragma once
// `penumbra eval ate|rpe GROUND_TRUTH ESTIMATE [options]`: trajectory metrics of an estimate
// against ground truth, both TUM-format files (eval/, docs/evaluation.md). the report goes to
// stdout as text (or JSON with --format json); --json FILE and --plot FILE.png write files.

#include <memory>

namespace CLI {
class App;
}

namespace penumbra {

/// the `eval` verb: its options registered on a CLI11 app, and its run.
class EvalCommand {
 public:
  /// registers `eval` with its sub-verbs `ate` and `rpe` and their options on `app`.
  explicit EvalCommand(CLI::App& app);
  ~EvalCommand();
  EvalCommand(EvalCommand&&) noexcept;
  EvalCommand& operator=(EvalCommand&&) noexcept;

  /// true when the parsed command line chose `eval` (call after app.parse).
  bool Selected() const;

  /// reads both files, evaluates, writes the report to stdout and the --json / --plot files.
  /// returns the exit code (0).
  /// @throws ConfigError for an unreadable or malformed input file, too few associated poses,
  ///         or (rpe) no pose pair at the requested delta: bad input, exit code 2 in RunCli;
  ///         Error when an output file cannot be written (exit code 1).
  int Run() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

/// registers `penumbra eval` on `app` (EvalCommand's constructor).
EvalCommand AddEvalCommand(CLI::App& app);

}  // namespace penumbra
