#pragma once
// runs a piece of code in a forked child with a deadline, for tests of calls that used to
// block for ever (open() of a FIFO with no writer): a call that blocks fails the test after
// the deadline instead of hanging the test binary. the child reports through its exit status
// only; what it throws or prints is its own.

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <functional>
#include <string>
#include <thread>

namespace penumbra::testing {

/// the result of RunWithin: finished (with the child's exit status) or killed at the deadline.
struct WithinResult {
  bool finished = false;
  int exit_status = -1;
};

/// runs `body` in a forked child; its return value is the child's exit status (0 = pass).
/// the child is killed with SIGKILL if it has not finished after `seconds`.
inline WithinResult RunWithin(double seconds, const std::function<int()>& body) {
  const pid_t pid = fork();
  if (pid < 0) {
    ADD_FAILURE() << "fork failed";
    return {};
  }
  if (pid == 0) {
    int status = 99;
    try {
      status = body();
    } catch (...) {
      status = 98;
    }
    _exit(status);
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < deadline) {
    int status = 0;
    if (waitpid(pid, &status, WNOHANG) == pid)
      return {true, WIFEXITED(status) ? WEXITSTATUS(status) : -1};
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  kill(pid, SIGKILL);
  int status = 0;
  waitpid(pid, &status, 0);
  return {};
}

}  // namespace penumbra::testing
