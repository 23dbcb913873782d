#pragma once
// runs the real `penumbra` binary (PENUMBRA_BINARY, set by CMake for app_tests) as a
// child process: exit codes, signals and the stdout / stderr contract are tested on the
// program users run, not on RunCli in-process.

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "common/temp_dir.h"

extern char** environ;

namespace penumbra::testing {

/// a started child process with stdout and stderr captured to files.
class ChildProcess {
 public:
  /// starts PENUMBRA_BINARY with `args` (without argv[0]); stdout / stderr go to
  /// `capture_dir`/stdout.txt and stderr.txt.
  ChildProcess(const std::vector<std::string>& args, const std::filesystem::path& capture_dir)
      : out_path_(capture_dir / "stdout.txt"), err_path_(capture_dir / "stderr.txt") {
    std::vector<std::string> argv_s = {PENUMBRA_BINARY};
    argv_s.insert(argv_s.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& a : argv_s) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 1, out_path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_addopen(&fa, 2, err_path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int rc = posix_spawn(&pid_, argv[0], &fa, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&fa);
    if (rc != 0) throw std::runtime_error("posix_spawn " + argv_s[0] + " failed");
  }
  ~ChildProcess() {
    if (pid_ > 0) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
  }
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  void Signal(int sig) const { kill(pid_, sig); }
  /// the child's process id (-1 once waited for).
  pid_t pid() const { return pid_; }

  /// waits for the exit; returns the exit code, or 128 + signal if a signal killed it.
  int Wait() {
    int status = 0;
    waitpid(pid_, &status, 0);
    pid_ = -1;
    if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
    return WEXITSTATUS(status);
  }

  /// waits at most `seconds` for the exit; returns the exit code (or 128 + signal), or -1 if
  /// the child still runs then (it is left running).
  int WaitFor(double seconds) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (true) {
      int status = 0;
      const pid_t r = waitpid(pid_, &status, WNOHANG);
      if (r == pid_) {
        pid_ = -1;
        if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
        return WEXITSTATUS(status);
      }
      if (std::chrono::steady_clock::now() > deadline) return -1;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }

  std::string out() const { return ReadAll(out_path_); }
  std::string err() const { return ReadAll(err_path_); }

 private:
  pid_t pid_ = -1;
  std::filesystem::path out_path_, err_path_;
};

/// the result of a finished run of the binary.
struct ProcessResult {
  int exit_code = -1;  ///< exit status, or 128 + signal
  std::string out, err;
};

/// runs PENUMBRA_BINARY with `args` to completion.
inline ProcessResult RunPenumbra(const std::vector<std::string>& args,
                                 const std::filesystem::path& capture_dir) {
  ChildProcess p(args, capture_dir);
  ProcessResult r;
  r.exit_code = p.Wait();
  r.out = p.out();
  r.err = p.err();
  return r;
}

}  // namespace penumbra::testing
