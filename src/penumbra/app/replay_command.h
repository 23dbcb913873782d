#pragma once
// `penumbra replay FILE.plog ...`: a recorded run (a run log, `penumbra run --record`) rendered
// again under other visual conditions (replay/replay_runner.h), or simulated again and checked
// against the log step by step (--resimulate, replay/resimulate.h). docs/replay.md.

#include <atomic>
#include <memory>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace penumbra {

/// the `replay` verb: its options registered on a CLI11 app, and its run.
class ReplayCommand {
 public:
  /// registers `replay` and its options on `app`.
  explicit ReplayCommand(CLI::App& app);
  ~ReplayCommand();
  ReplayCommand(ReplayCommand&&) noexcept;
  ReplayCommand& operator=(ReplayCommand&&) noexcept;

  /// true when the parsed command line chose `replay` (call after app.parse).
  bool Selected() const;

  /// runs the replay (or the resimulation); `command_line` (argv) goes into run.json;
  /// `stop_request` (may be null) is set by the SIGINT / SIGTERM handler. returns the exit code: 0
  /// done (bit-exact for --resimulate), 3 when the resimulation diverged (the first divergence is
  /// printed on stdout), 128 + signal when stopped by a signal (outputs and run.json written).
  /// @throws ConfigError for bad options or input (exit code 2 in RunCli), RunLogError for a
  ///         file that is not a readable run log, Error for a write failure or a run log that
  ///         cannot be read (exit code 1).
  int Run(const std::vector<std::string>& command_line, const std::atomic<int>* stop_request) const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

/// registers `penumbra replay` on `app` (ReplayCommand's constructor).
ReplayCommand AddReplayCommand(CLI::App& app);

}  // namespace penumbra
