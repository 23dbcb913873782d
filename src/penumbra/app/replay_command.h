#pragma once
// `penumbra replay FILE.plog ...`: a recorded run (a run log, `penumbra run --record`) rendered
// again under other visual conditions (replay/kinematic/replay_runner.h), or simulated again and
// checked against the log step by step (--resimulate, replay/resimulate.h). docs/replay.md.

#include <atomic>
#include <memory>
#include <string>
#include <vector>

#include "penumbra/app/command.h"

namespace penumbra {

/// the `replay` verb (app/command.h).
class ReplayCommand : public Command {
 public:
  ReplayCommand();
  ~ReplayCommand() override;
  ReplayCommand(const ReplayCommand&) = delete;
  ReplayCommand& operator=(const ReplayCommand&) = delete;

  std::string name() const override;
  std::string summary() const override;
  /// adds the log argument and the options to `replay`.
  void AddOptions(CLI::App* replay) override;
  /// runs the replay (or the resimulation) with SIGINT / SIGTERM handlers installed
  /// (app/stop_signals.h); the command line (argv) goes into run.json. returns the exit code: 0
  /// done (bit-exact for --resimulate), 3 when the resimulation diverged (the first divergence is
  /// printed on stdout), 128 + signal when stopped by a signal (outputs and run.json written).
  /// @throws ConfigError for bad options or input (exit code 2 in RunCli), RunLogError for a
  ///         file that is not a readable run log, Error for a write failure or a run log that
  ///         cannot be read (exit code 1).
  int Run(const CommandArgs& args) override;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace penumbra
