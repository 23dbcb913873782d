#pragma once
// running one benchmark method: its command template expanded into an argument vector
// (campaign/command_template.h) and executed without a shell in the method's work folder,
// with its stdout and stderr written to files there, killed (its whole process group, SIGTERM
// then SIGKILL after 2 s) when it runs past its timeout or when a stop is requested.

#include <atomic>
#include <string>
#include <vector>

namespace penumbra {

/// how the process ended.
struct ProcessOutcome {
  bool timed_out = false;
  bool stopped = false;  ///< killed because of a stop request
  int exit_code = -1;    ///< when it exited normally (127 when it could not be started)
  int signal = 0;        ///< when a signal ended it (0 = none)
  double wall_sec = 0;
  std::string start_error;  ///< why it could not be started ("" when it was)
  /// "exit 0", "exit 3", "signal 11 (SIGSEGV)", "timeout after 600 s", "cannot run 'x': ...".
  std::string Describe() const;
  bool ok() const { return !timed_out && !stopped && signal == 0 && exit_code == 0; }
};

/// runs `argv` (argv[0] a path, or a name looked up on PATH) in `workdir` (created if missing),
/// stdin from /dev/null, stdout to workdir/stdout.log, stderr to workdir/stderr.log, in a new
/// process group; waits until it exits, runs past `timeout_sec` or *stop_request is set.
/// a program that cannot be started is an outcome (exit 127 with start_error), not an error.
/// @throws Error if argv is empty or no process can be created.
ProcessOutcome RunMethodCommand(const std::vector<std::string>& argv, const std::string& workdir,
                                double timeout_sec, const std::atomic<int>* stop_request = nullptr);

/// the command.sh written beside a method's logs for people to re-run it by hand: a /bin/sh
/// script that enters `workdir` and executes `argv`, every word quoted by ShellCommandLine
/// (campaign/shell_quote.h), so it runs exactly the argument vector the harness ran.
/// @throws Error when a word holds a NUL byte.
std::string MethodCommandScript(const std::vector<std::string>& argv, const std::string& workdir);

}  // namespace penumbra
