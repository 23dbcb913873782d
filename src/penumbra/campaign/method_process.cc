#include "penumbra/campaign/method_process.h"

#include <string.h>

#include <chrono>
#include <filesystem>
#include <thread>

#include "penumbra/campaign/child_process.h"
#include "penumbra/campaign/shell_quote.h"

namespace penumbra {

std::string ProcessOutcome::Describe() const {
  if (!start_error.empty()) return start_error;
  if (timed_out) return "timeout after " + std::to_string(static_cast<int>(wall_sec)) + " s";
  if (stopped) return "stopped";
  if (signal != 0) {
    const char* name = sigabbrev_np(signal);
    return "signal " + std::to_string(signal) + (name ? std::string(" (SIG") + name + ")" : "");
  }
  return "exit " + std::to_string(exit_code);
}

ProcessOutcome RunMethodCommand(const std::vector<std::string>& argv, const std::string& workdir,
                                double timeout_sec, const std::atomic<int>* stop_request) {
  std::filesystem::create_directories(workdir);
  const auto start = std::chrono::steady_clock::now();
  ChildProcess child(argv, workdir, workdir + "/stdout.log", workdir + "/stderr.log",
                     /*search_path=*/true);
  ProcessOutcome outcome;
  outcome.start_error = child.start_error();
  while (!child.Exited()) {
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (elapsed > timeout_sec) outcome.timed_out = true;
    if (stop_request && stop_request->load() != 0) outcome.stopped = true;
    if (outcome.timed_out || outcome.stopped) {
      child.TerminateAndWait(2.0);
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(elapsed < 1 ? 5 : 50));
  }
  outcome.wall_sec = child.wall_sec();
  outcome.exit_code = child.exit_code();
  outcome.signal = child.signal();
  return outcome;
}

std::string MethodCommandScript(const std::vector<std::string>& argv, const std::string& workdir) {
  return "#!/bin/sh\n# the command penumbra benchmark ran (without a shell), one word per "
         "argument\n"
         "cd " +
         ShellQuote(workdir) + " || exit 1\nexec " + ShellCommandLine(argv) + "\n";
}

}  // namespace penumbra
