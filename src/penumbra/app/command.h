#pragma once
// one verb of the `penumbra` command line. every verb implements Command, and the one list of
// verbs (app/command_list.h CommandList) is what RunCli (app/cli.h) builds the command line
// from: each verb's words, one-line summary (the `--help` lists) and options (its usage and its
// own `--help`) come from its Command, and RunCli runs the verb that was given.
//
// adding a verb: a class implementing Command (in app/, calling the code that does the work in
// its own module), one entry in CommandList(), and its line in README.md's command-line block
// and docs (tests/app/command_list_test.cc checks that every verb is listed there).

#include <atomic>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace penumbra {

/// what a verb's Run gets besides its parsed options.
struct CommandArgs {
  /// the whole command line as given (argv), e.g. recorded in run.json.
  std::vector<std::string> command_line;
  /// the process's stop request: 0 until SIGINT or SIGTERM arrives while a verb that installed
  /// StopSignals (app/stop_signals.h) runs, then the signal's number. never null.
  std::atomic<int>* stop_signal = nullptr;
};

/// one verb of the command line (see the file comment). a Command object lives for one RunCli
/// call: AddOptions binds its options to its own members, Run reads them after the parse.
class Command {
 public:
  virtual ~Command() = default;

  /// the verb's words as typed, e.g. "run" or "bench render" (a group word first, then the
  /// verb; the group's summary comes from CommandGroups()).
  virtual std::string name() const = 0;
  /// one line for the verb lists of `penumbra --help` and `penumbra GROUP --help`.
  virtual std::string summary() const = 0;
  /// declares the verb's positional arguments, options and sub-verbs on `verb` (the CLI11
  /// subcommand RunCli made for name()): its usage and `--help` text.
  virtual void AddOptions(CLI::App* verb) = 0;
  /// runs the verb with the options parsed into this object.
  /// @return the process exit code (0 ok, 1 runtime failure, 2 bad input, ...).
  /// @throws ConfigError for bad input (RunCli prints it and exits 2) and any other exception
  ///         for a runtime failure (exit 1).
  virtual int Run(const CommandArgs& args) = 0;
};

}  // namespace penumbra
