#pragma once
// a child process of the benchmark harness that runs beside others (the simulator and a
// navigation method of one nav job): started in its own process group with stdout and stderr
// to files, polled without blocking, and ended cleanly (SIGTERM to its group, SIGKILL after a
// grace period). no shell is involved: the argument vector is executed as it is.

#include <optional>
#include <string>
#include <vector>

namespace penumbra {

/// one child process (see the file comment). not copyable; the destructor kills a child that
/// is still running (SIGKILL to its group) and reaps it.
class ChildProcess {
 public:
  /// starts `argv` in `workdir` (created if missing), stdin from /dev/null, stdout and stderr
  /// to the files given (truncated), in a new process group, SIGINT and SIGTERM at their
  /// defaults; the child gets SIGTERM when this process dies (PR_SET_PDEATHSIG). argv[0] is a
  /// path, or with `search_path` a name looked up on PATH as execvp does (a relative path is
  /// relative to `workdir`). a program that cannot be executed (not found, not executable) or a
  /// workdir / log file that cannot be opened is not an exception: the child exits 127 at once
  /// and start_error() says why.
  /// @throws Error if argv is empty or fork fails.
  ChildProcess(const std::vector<std::string>& argv, const std::string& workdir,
               const std::string& stdout_path, const std::string& stderr_path,
               bool search_path = false);
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

  /// "exit N", "signal N (SIGNAME)"; "running" before it exited; start_error() when set.
  std::string Describe() const;
  bool exited() const { return exited_; }
  int exit_code() const { return exit_code_; }   ///< -1 unless it exited normally
  int signal() const { return signal_; }         ///< 0 unless a signal ended it
  double wall_sec() const { return wall_sec_; }  ///< from start to exit, s
  int pid() const { return pid_; }
  /// why the program could not be started ("cannot run 'x': No such file or directory"), ""
  /// when it was.
  const std::string& start_error() const { return start_error_; }

 private:
  int pid_ = -1;
  std::string start_error_;
  bool exited_ = false, terminated_ = false;
  int exit_code_ = -1, signal_ = 0;
  double start_ = 0, wall_sec_ = 0, term_time_ = 0;
};

/// runs `argv` (argv[0] looked up on PATH) with stdin from /dev/null, stderr to /dev/null or,
/// with `merge_stderr`, into the captured output, and waits for it; no shell is involved.
/// returns its stdout, or nullopt when it exited non-zero or could not be started (its exit
/// code in *exit_code when given: 127 when it could not be started, -1 for a signal).
std::optional<std::string> CaptureCommand(const std::vector<std::string>& argv,
                                          bool merge_stderr = false, int* exit_code = nullptr);

/// the path of executable `name` on PATH ("" when there is none), as execvp would find it.
std::string FindOnPath(const std::string& name);

}  // namespace penumbra
