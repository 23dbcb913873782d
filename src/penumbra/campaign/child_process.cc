#include "penumbra/campaign/child_process.h"

#include <fcntl.h>
#include <signal.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <thread>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

double Now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

ChildProcess::ChildProcess(const std::vector<std::string>& argv, const std::string& workdir,
                           const std::string& stdout_path, const std::string& stderr_path,
                           bool search_path) {
  if (argv.empty()) throw Error("ChildProcess: empty command");
  std::error_code ec;
  std::filesystem::create_directories(workdir, ec);
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const bool same_log = stdout_path == stderr_path;
  // the child reports a failed start (stage, errno) through a pipe that exec closes
  int report[2];
  if (pipe2(report, O_CLOEXEC) != 0)
    throw Error(std::string("cannot start ") + argv[0] + ": pipe: " + strerror(errno));
  const pid_t parent = getpid();
  start_ = Now();
  pid_ = fork();
  if (pid_ < 0) {
    const int e = errno;
    close(report[0]);
    close(report[1]);
    throw Error(std::string("cannot start ") + argv[0] + ": " + strerror(e));
  }
  if (pid_ == 0) {
    // only async-signal-safe calls from here on
    close(report[0]);
    const auto fail = [&](int stage) {
      const int msg[2] = {stage, errno};
      const ssize_t ignored = write(report[1], msg, sizeof msg);
      (void)ignored;
      _exit(127);
    };
    setpgid(0, 0);
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent) _exit(127);
    const int out = open(stdout_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (out < 0) fail(1);
    const int err =
        same_log ? out : open(stderr_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (err < 0) fail(2);
    const int in = open("/dev/null", O_RDONLY | O_CLOEXEC);
    if (in < 0) fail(3);
    if (chdir(workdir.c_str()) != 0) fail(4);
    dup2(in, 0);
    dup2(out, 1);
    dup2(err, 2);
    // the harness's SIGINT/SIGTERM handling is not the child's
    ::signal(SIGINT, SIG_DFL);
    ::signal(SIGTERM, SIG_DFL);
    if (search_path)
      execvp(args[0], args.data());
    else
      execv(args[0], args.data());
    fail(5);
  }
  close(report[1]);
  setpgid(pid_, pid_);
  int msg[2] = {0, 0};
  ssize_t n;
  do {
    n = read(report[0], msg, sizeof msg);
  } while (n < 0 && errno == EINTR);
  close(report[0]);
  if (n == static_cast<ssize_t>(sizeof msg)) {
    const std::string what =
        msg[0] == 1   ? "cannot open its stdout file '" + stdout_path + "'"
        : msg[0] == 2 ? "cannot open its stderr file '" + stderr_path + "'"
        : msg[0] == 3 ? std::string("cannot open /dev/null")
        : msg[0] == 4
            ? "cannot enter its work folder '" + workdir + "'"
            : "cannot run '" + argv[0] + "'" +
                  (search_path && argv[0].find('/') == std::string::npos ? " (searched PATH)" : "");
    start_error_ = SanitizeForMessage(what, 600) + ": " + strerror(msg[1]);
  }
}

ChildProcess::~ChildProcess() {
  if (pid_ > 0 && !Exited()) {
    kill(-pid_, SIGKILL);
    int status = 0;
    waitpid(pid_, &status, 0);
  }
}

bool ChildProcess::Exited() {
  if (exited_) return true;
  int status = 0;
  const pid_t r = waitpid(pid_, &status, WNOHANG);
  if (r != pid_) return false;
  exited_ = true;
  wall_sec_ = Now() - start_;
  if (WIFEXITED(status)) exit_code_ = WEXITSTATUS(status);
  if (WIFSIGNALED(status)) signal_ = WTERMSIG(status);
  kill(-pid_, SIGKILL);  // leftovers of its group (a daemonised grandchild)
  return true;
}

void ChildProcess::Terminate() {
  if (Exited()) return;
  kill(-pid_, SIGTERM);
  if (!terminated_) term_time_ = Now();
  terminated_ = true;
}

void ChildProcess::TerminateAndWait(double grace_sec) {
  Terminate();
  bool killed = false;
  while (!Exited()) {
    if (!killed && Now() - term_time_ > grace_sec) {
      kill(-pid_, SIGKILL);
      killed = true;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

bool ChildProcess::WaitFor(double timeout_sec) {
  const double until = Now() + timeout_sec;
  while (!Exited()) {
    if (Now() > until) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return true;
}

std::string ChildProcess::Describe() const {
  if (!start_error_.empty()) return start_error_;
  if (!exited_) return "running";
  if (signal_ != 0) {
    const char* name = sigabbrev_np(signal_);
    return "signal " + std::to_string(signal_) + (name ? std::string(" (SIG") + name + ")" : "");
  }
  return "exit " + std::to_string(exit_code_);
}

std::optional<std::string> CaptureCommand(const std::vector<std::string>& argv, bool merge_stderr,
                                          int* exit_code) {
  if (exit_code) *exit_code = -1;
  if (argv.empty()) return std::nullopt;
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  int pipe_fd[2];
  if (pipe2(pipe_fd, O_CLOEXEC) != 0) return std::nullopt;
  const pid_t pid = fork();
  if (pid < 0) {
    close(pipe_fd[0]);
    close(pipe_fd[1]);
    return std::nullopt;
  }
  if (pid == 0) {
    const int in = open("/dev/null", O_RDONLY | O_CLOEXEC);
    const int null_out = open("/dev/null", O_WRONLY | O_CLOEXEC);
    if (in < 0 || null_out < 0) _exit(127);
    dup2(in, 0);
    dup2(pipe_fd[1], 1);
    dup2(merge_stderr ? pipe_fd[1] : null_out, 2);
    ::signal(SIGINT, SIG_DFL);
    ::signal(SIGTERM, SIG_DFL);
    execvp(args[0], args.data());
    _exit(127);
  }
  close(pipe_fd[1]);
  std::string out;
  char buf[4096];
  for (;;) {
    const ssize_t n = read(pipe_fd[0], buf, sizeof buf);
    if (n > 0) {
      out.append(buf, static_cast<size_t>(n));
    } else if (n == 0 || errno != EINTR) {
      break;
    }
  }
  close(pipe_fd[0]);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (exit_code) *exit_code = code;
  if (code != 0) return std::nullopt;
  return out;
}

std::string FindOnPath(const std::string& name) {
  if (name.empty()) return "";
  if (name.find('/') != std::string::npos) return access(name.c_str(), X_OK) == 0 ? name : "";
  const char* env = getenv("PATH");
  const std::string path = env ? env : "/usr/local/bin:/usr/bin:/bin";
  size_t pos = 0;
  while (pos <= path.size()) {
    const size_t end = std::min(path.find(':', pos), path.size());
    const std::string dir = end > pos ? path.substr(pos, end - pos) : ".";
    const std::string file = dir + "/" + name;
    std::error_code ec;
    if (std::filesystem::is_regular_file(file, ec) && access(file.c_str(), X_OK) == 0) return file;
    pos = end + 1;
  }
  return "";
}

}  // namespace penumbra
