#pragma once
// running one SLAM method: a command template (benchmark/benchmark_spec.h) filled in and run
// by /bin/sh in the method's work folder, with its stdout and stderr written to files there,
// killed (its whole process group, SIGTERM then SIGKILL after 2 s) when it runs past its
// timeout or when a stop is requested.

#include <atomic>
#include <map>
#include <string>

namespace penumbra {

/// how the process ended.
struct ProcessOutcome {
  bool timed_out = false;
  bool stopped = false;  ///< killed because of a stop request
  int exit_code = -1;    ///< when it exited normally
  int signal = 0;        ///< when a signal ended it (0 = none)
  double wall_sec = 0;
  /// "exit 0", "exit 3", "signal 11 (SIGSEGV)", "timeout after 600 s", ...
  std::string Describe() const;
  bool ok() const { return !timed_out && !stopped && signal == 0 && exit_code == 0; }
};

/// `text` with each `{key}` replaced by values.at(key) (`{{` / `}}` become braces).
/// @throws Error for a placeholder not in `values` (templates are checked at spec load).
std::string FillTemplate(const std::string& text, const std::map<std::string, std::string>& values);

/// `s` quoted for /bin/sh ('...' with embedded quotes escaped).
std::string ShellQuote(const std::string& s);

/// runs `/bin/sh -c command` in `workdir` (created if missing), stdout to
/// workdir/stdout.log, stderr to workdir/stderr.log, in a new process group.
/// @throws Error if the process cannot be started.
ProcessOutcome RunShellCommand(const std::string& command, const std::string& workdir,
                               double timeout_sec, const std::atomic<int>* stop_request = nullptr);

}  // namespace penumbra
