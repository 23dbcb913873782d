#pragma once
// a child process of the benchmark harness that runs beside others (the simulator and a
// navigation method of one nav job): started in its own process group with stdout and stderr
// to files, polled without blocking, and ended cleanly (SIGTERM to its group, SIGKILL after a
// grace period).

#include <string>
#include <vector>

namespace penumbra {

/// one child process (see the file comment). not copyable; the destructor kills a child that
/// is still running (SIGKILL to its group) and reaps it.
class ChildProcess {
 public:
  /// starts `argv` (argv[0] a path, no PATH search) in `workdir` (created if missing), stdin
  /// from /dev/null, stdout and stderr to the files given (truncated), in a new process group.
  /// @throws Error if argv is empty or the process cannot be started.
  ChildProcess(const std::vector<std::string>& argv, const std::string& workdir,
               const std::string& stdout_path, const std::string& stderr_path);
  ~ChildProcess();
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  /// true once the child has exited (reaps it without blocking).
  bool Exited();
  /// SIGTERM to the child's group (no-op once it exited); the clock for KillAfter starts.
  void Terminate();
  /// waits until the child exits; after `grace_sec` from the first Terminate (or from this call
  /// when none was sent) its group gets SIGKILL. sends SIGTERM first if none was sent.
  void TerminateAndWait(double grace_sec);
  /// waits without signalling until it exits or `timeout_sec` passes; true when it exited.
  bool WaitFor(double timeout_sec);

  /// "exit N", "signal N (SIGNAME)"; "running" before it exited.
  std::string Describe() const;
  bool exited() const { return exited_; }
  int exit_code() const { return exit_code_; }   ///< -1 unless it exited normally
  int signal() const { return signal_; }         ///< 0 unless a signal ended it
  double wall_sec() const { return wall_sec_; }  ///< from start to exit, s
  int pid() const { return pid_; }

 private:
  int pid_ = -1;
  bool exited_ = false, terminated_ = false;
  int exit_code_ = -1, signal_ = 0;
  double start_ = 0, wall_sec_ = 0, term_time_ = 0;
};

}  // namespace penumbra
