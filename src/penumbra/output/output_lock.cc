#include "penumbra/output/output_lock.h"

#include <fcntl.h>
#include <spdlog/spdlog.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <cerrno>
#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <utility>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

std::string Holder(int fd) {
  const int pid = LockHolderPid(fd);
  return pid > 0 ? "another run (PID " + std::to_string(pid) + ")" : "another run (PID unknown)";
}

// a file system without flock(2) (some FUSE and network mounts): the run goes on unlocked,
// with a warning, rather than not at all
bool LocksUnsupported(int err) {
  return err == ENOLCK || err == EOPNOTSUPP || err == ENOSYS || err == EINVAL;
}

// an exclusive flock on `fd` without waiting. 0: locked, or the file system has no flock
// (warned, the run goes on unlocked); else the errno (EWOULDBLOCK: another holds it)
int LockOrWarn(int fd, const std::string& what) {
  if (::flock(fd, LOCK_EX | LOCK_NB) == 0) return 0;
  const int err = errno;
  if (!LocksUnsupported(err)) return err;
  spdlog::warn("{} cannot be locked ({}): another run could write into it at the same time", what,
               std::strerror(err));
  return 0;
}

bool SameFile(const struct stat& a, const struct stat& b) {
  return a.st_dev == b.st_dev && a.st_ino == b.st_ino;
}

}  // namespace

int LockHolderPid(int fd) {
  struct stat st {};
  if (::fstat(fd, &st) != 0) return 0;
  std::ifstream locks("/proc/locks");
  const unsigned want_major = major(st.st_dev), want_minor = minor(st.st_dev);
  int inode_only = 0, inode_matches = 0;
  std::string line;
  // a line: "1: FLOCK  ADVISORY  WRITE 4242 08:01:1311 0 EOF" (waiters have "->" after the id)
  for (int n = 0; n < 100000 && std::getline(locks, line); ++n) {
    if (line.size() > 256 || line.find("->") != std::string::npos) continue;
    char type[16] = {}, mode[16] = {}, rw[16] = {};
    int pid = 0;
    unsigned maj = 0, min = 0;
    uintmax_t ino = 0;
    if (std::sscanf(line.c_str(), "%*d: %15s %15s %15s %d %x:%x:%ju", type, mode, rw, &pid, &maj,
                    &min, &ino) != 7)
      continue;
    if (std::strcmp(type, "FLOCK") != 0 || ino != static_cast<uintmax_t>(st.st_ino)) continue;
    if (maj == want_major && min == want_minor) return pid;
    inode_only = pid;
    ++inode_matches;
  }
  // a file system that reports another device number there (e.g. overlayfs): the inode alone
  return inode_matches == 1 ? inode_only : 0;
}

OutputLock LockOutputFolder(const std::filesystem::path& dir, const std::string& key) {
  auto fail = [&](const std::string& what) {
    return ConfigError("", 0, key, "output folder '" + dir.string() + "' " + what);
  };
  UniqueFd fd(::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (fd.get() < 0) throw fail(std::string("cannot be opened: ") + std::strerror(errno));
  if (const int err = LockOrWarn(fd.get(), "output folder '" + dir.string() + "'")) {
    if (err == EWOULDBLOCK)
      throw fail("is in use by " + Holder(fd.get()) +
                 "; wait for it to end or choose another folder (--force never removes the "
                 "outputs of a running run)");
    throw fail(std::string("cannot be locked: ") + std::strerror(err));
  }
  // the name still leads to the folder locked (not removed and made anew meanwhile)
  struct stat held {
  }, named{};
  if (::fstat(fd.get(), &held) != 0 || ::stat(dir.c_str(), &named) != 0 || !SameFile(held, named))
    throw fail("was removed or replaced while it was being locked; run again");
  return OutputLock(std::move(fd));
}

LockedRunLogFile OpenRunLogFile(const std::string& path, bool replace, const std::string& key) {
  auto fail = [&](const std::string& what) {
    return ConfigError("", 0, key, "run log '" + path + "' " + what);
  };
  auto in_use = [&](int fd) {
    return fail("is being written by " + Holder(fd) +
                "; wait for it to end or choose another file (--force never replaces the log of "
                "a running run)");
  };
  LockedRunLogFile f;
  f.path = path;
  f.fd = UniqueFd(::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644));
  if (f.fd.get() >= 0) {
    // another run that replaces it (--force) may have taken it in between
    if (LockOrWarn(f.fd.get(), "run log '" + path + "'") != 0) throw in_use(f.fd.get());
    f.created = true;
    return f;
  }
  if (errno != EEXIST) throw fail(std::string("cannot be created: ") + std::strerror(errno));
  struct stat named {};
  if (::lstat(path.c_str(), &named) != 0)
    throw fail(std::string("cannot be opened: ") + std::strerror(errno));
  if (S_ISLNK(named.st_mode))
    throw fail("is a symbolic link; expected a new file (links are not followed)");
  if (!S_ISREG(named.st_mode)) throw fail("exists and is not a regular file; expected a new file");
  f.fd = UniqueFd(::open(path.c_str(), O_WRONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC));
  struct stat held {};
  if (f.fd.get() < 0 || ::fstat(f.fd.get(), &held) != 0)
    throw fail(std::string("cannot be opened: ") + std::strerror(errno));
  if (!S_ISREG(held.st_mode) || !SameFile(held, named))
    throw fail("was replaced while it was being opened; run again");
  if (const int err = LockOrWarn(f.fd.get(), "run log '" + path + "'")) {
    if (err == EWOULDBLOCK) throw in_use(f.fd.get());
    throw fail(std::string("cannot be locked: ") + std::strerror(err));
  }
  if (!replace)
    throw fail(
        "exists; choose a new file, or pass --force to replace it (an existing run log is "
        "never overwritten otherwise)");
  if (::ftruncate(f.fd.get(), 0) != 0)
    throw fail(std::string("cannot be truncated: ") + std::strerror(errno));
  const int flags = ::fcntl(f.fd.get(), F_GETFL);
  if (flags >= 0) ::fcntl(f.fd.get(), F_SETFL, flags & ~O_NONBLOCK);
  return f;
}

}  // namespace penumbra
