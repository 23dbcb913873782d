#pragma once
// one run per output folder and per run log: a run holds an exclusive advisory lock (flock(2))
// on its output folder and on the run log it writes (--record) for its whole life. a second run
// into the same folder or log fails at start naming the other run's PID (read from /proc/locks),
// and --force never removes or truncates what a live run holds: the lock is taken before
// anything is removed. the locks go with the open descriptors: a killed run leaves none behind,
// and nothing is added to the folder. on a file system without flock(2) (ENOLCK, EOPNOTSUPP,
// ENOSYS, EINVAL: some FUSE and network mounts) the run goes on unlocked with a warning.

#include <filesystem>
#include <string>

#include "penumbra/core/output_path_policy.h"

namespace penumbra {

/// an exclusive flock(2) lock held through an open descriptor; released when destroyed
/// (move-only).
class OutputLock {
 public:
  OutputLock() = default;
  /// takes over `fd`, which holds the lock.
  explicit OutputLock(UniqueFd fd) : fd_(std::move(fd)) {}
  /// whether a lock is held.
  bool held() const { return fd_.get() >= 0; }

 private:
  UniqueFd fd_;
};

/// the process holding a flock(2) lock on the file or folder open as `fd`, from /proc/locks;
/// 0 when none is found or it cannot be told (another PID namespace, no /proc).
int LockHolderPid(int fd);

/// locks the existing folder `dir` (an output folder) for this process's run.
/// @param key  where `dir` came from, named in errors: "--out" or "output.dir"
/// @throws ConfigError (key `key`) when another run holds it ("is in use by another run (PID
///         N)"), when it cannot be opened or locked, or when it was replaced while being locked.
OutputLock LockOutputFolder(const std::filesystem::path& dir, const std::string& key);

/// a run log file opened for writing and locked (OpenRunLogFile).
struct LockedRunLogFile {
  UniqueFd fd;           ///< open for writing, empty, locked (the lock goes with the descriptor)
  std::string path;      ///< the path as given
  bool created = false;  ///< the file was made by this call (it did not exist)
};

/// opens the run log `path` (the user's --record) for a new log: a new file is created with
/// O_CREAT | O_EXCL | O_NOFOLLOW; an existing one is replaced (truncated) only with `replace`
/// (the user's --force) and never while another run holds it. a symbolic link is never followed,
/// anything but a regular file is refused.
/// @param key  named in errors ("--record")
/// @throws ConfigError (key `key`) naming the path: in use by another run (with its PID),
///         existing without `replace`, a symbolic link, not a regular file, or the system's
///         reason it could not be created, opened, locked or truncated.
LockedRunLogFile OpenRunLogFile(const std::string& path, bool replace, const std::string& key);

}  // namespace penumbra
