#include "penumbra/benchmark/child_process.h"

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
namespace {

double Now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

ChildProcess::ChildProcess(const std::vector<std::string>& argv, const std::string& workdir,
                           const std::string& stdout_path, const std::string& stderr_path) {
  if (argv.empty()) throw Error("ChildProcess: empty command");
  std::filesystem::create_directories(workdir);
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  start_ = Now();
  pid_ = fork();
  if (pid_ < 0) throw Error(std::string("cannot start ") + argv[0] + ": " + strerror(errno));
  if (pid_ == 0) {
    setpgid(0, 0);
    const int out = open(stdout_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    const int err = open(stderr_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    const int in = open("/dev/null", O_RDONLY | O_CLOEXEC);
    if (out < 0 || err < 0 || in < 0 || chdir(workdir.c_str()) != 0) _exit(127);
    dup2(in, 0);
    dup2(out, 1);
    dup2(err, 2);
    // the harness's SIGINT/SIGTERM handling is not the child's
    ::signal(SIGINT, SIG_DFL);
    ::signal(SIGTERM, SIG_DFL);
    execv(args[0], args.data());
    _exit(127);
  }
  setpgid(pid_, pid_);
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
  if (!exited_) return "running";
  if (signal_ != 0) {
    const char* name = sigabbrev_np(signal_);
    return "signal " + std::to_string(signal_) + (name ? std::string(" (SIG") + name + ")" : "");
  }
  return "exit " + std::to_string(exit_code_);
}

}  // namespace penumbra
