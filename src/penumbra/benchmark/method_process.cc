#include "penumbra/benchmark/method_process.h"

#include <fcntl.h>
#include <signal.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <thread>

#include "penumbra/core/error.h"

namespace penumbra {

std::string ProcessOutcome::Describe() const {
  if (timed_out) return "timeout after " + std::to_string(static_cast<int>(wall_sec)) + " s";
  if (stopped) return "stopped";
  if (signal != 0) {
    const char* name = sigabbrev_np(signal);
    return "signal " + std::to_string(signal) + (name ? std::string(" (SIG") + name + ")" : "");
  }
  return "exit " + std::to_string(exit_code);
}

std::string FillTemplate(const std::string& text,
                         const std::map<std::string, std::string>& values) {
  std::string out;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if ((c == '{' || c == '}') && i + 1 < text.size() && text[i + 1] == c) {
      out += c;
      ++i;
      continue;
    }
    if (c != '{') {
      out += c;
      continue;
    }
    const size_t end = text.find('}', i);
    const std::string key = end == std::string::npos ? "" : text.substr(i + 1, end - i - 1);
    const auto it = values.find(key);
    if (it == values.end()) throw Error("command template: unknown placeholder '{" + key + "}'");
    out += it->second;
    i = end;
  }
  return out;
}

std::string ShellQuote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

ProcessOutcome RunShellCommand(const std::string& command, const std::string& workdir,
                               double timeout_sec, const std::atomic<int>* stop_request) {
  std::filesystem::create_directories(workdir);
  const std::string out_path = workdir + "/stdout.log", err_path = workdir + "/stderr.log";
  const auto start = std::chrono::steady_clock::now();
  const pid_t pid = fork();
  if (pid < 0) throw Error(std::string("cannot start a method process: ") + strerror(errno));
  if (pid == 0) {
    setpgid(0, 0);
    const int out = open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    const int err = open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    const int in = open("/dev/null", O_RDONLY | O_CLOEXEC);
    if (out < 0 || err < 0 || in < 0 || chdir(workdir.c_str()) != 0) _exit(127);
    dup2(in, 0);
    dup2(out, 1);
    dup2(err, 2);
    execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  setpgid(pid, pid);
  ProcessOutcome outcome;
  int status = 0;
  bool killed = false;
  std::chrono::steady_clock::time_point kill_time;
  for (;;) {
    const pid_t r = waitpid(pid, &status, WNOHANG);
    if (r == pid) break;
    if (r < 0 && errno != EINTR) throw Error(std::string("waitpid: ") + strerror(errno));
    const auto now = std::chrono::steady_clock::now();
    const double elapsed = std::chrono::duration<double>(now - start).count();
    if (!killed) {
      if (elapsed > timeout_sec) outcome.timed_out = true;
      if (stop_request && stop_request->load() != 0) outcome.stopped = true;
      if (outcome.timed_out || outcome.stopped) {
        kill(-pid, SIGTERM);
        killed = true;
        kill_time = now;
      }
    } else if (std::chrono::duration<double>(now - kill_time).count() > 2.0) {
      kill(-pid, SIGKILL);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(elapsed < 1 ? 5 : 50));
  }
  kill(-pid, SIGKILL);  // leftovers of the group (a daemonised child)
  outcome.wall_sec =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (WIFEXITED(status)) outcome.exit_code = WEXITSTATUS(status);
  if (WIFSIGNALED(status)) outcome.signal = WTERMSIG(status);
  return outcome;
}

}  // namespace penumbra
