#include "penumbra/dataset/run_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <vector>

#include "penumbra/core/error.h"
#include "penumbra/core/output_path_policy.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

// the error for an entry `name` of the folder `dir_fd` (shown as `shown`) that could not be
// opened with errno `err`
[[noreturn]] void RefuseEntry(int dir_fd, const std::string& name, const fs::path& shown, int err,
                              const char* expected) {
  struct stat st {};
  if (fstatat(dir_fd, name.c_str(), &st, AT_SYMLINK_NOFOLLOW) == 0 && S_ISLNK(st.st_mode))
    throw ConfigError(shown.string(), 0, "",
                      std::string("is a symbolic link; export reads only what lies inside the "
                                  "run folder and follows no link, expected ") +
                          expected);
  if (err == ENOENT)
    throw ConfigError(shown.string(), 0, "",
                      std::string("missing; expected ") + expected + " in the run folder");
  throw ConfigError(shown.string(), 0, "",
                    std::string("cannot open: ") + std::strerror(err) + "; expected " + expected);
}

// opens the folder that holds the last component of `relative` (checked plain), walking down
// from run_dir without following links; sets *last to that component
int OpenParentFolder(const fs::path& run_dir, const fs::path& relative, std::string* last) {
  const fs::path shown = run_dir / relative;
  if (!IsPlainRelativePath(relative))
    throw ConfigError(shown.string(), 0, "",
                      "not a path inside the run folder (absolute, empty or with a '.' or '..' "
                      "component); expected a file or folder name inside it");
  UniqueFd dir(::open(run_dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (dir.get() < 0)
    throw ConfigError(run_dir.string(), 0, "",
                      std::string("cannot open the run folder: ") + std::strerror(errno));
  std::vector<std::string> parts;
  for (const fs::path& p : relative) parts.push_back(p.string());
  dir = OpenFoldersNoFollow(std::move(dir), parts, [&](int parent_fd, size_t i, int err) {
    fs::path walked = run_dir;
    for (size_t k = 0; k <= i; ++k) walked /= parts[k];
    RefuseEntry(parent_fd, parts[i], walked, err, "a folder");
  });
  *last = parts.back();
  return dir.release();
}

}  // namespace

bool IsPlainRelativePath(const fs::path& relative) {
  if (relative.empty() || relative.is_absolute() || relative.has_root_path()) return false;
  for (const fs::path& p : relative) {
    const std::string s = p.string();
    if (s.empty() || s == "." || s == "..") return false;
  }
  return true;
}

RunEntry StatRunEntry(const fs::path& run_dir, const fs::path& relative) {
  std::string last;
  const UniqueFd dir(OpenParentFolder(run_dir, relative, &last));
  struct stat st {};
  if (fstatat(dir.get(), last.c_str(), &st, AT_SYMLINK_NOFOLLOW) != 0) {
    if (errno == ENOENT) return RunEntry::kMissing;
    throw ConfigError((run_dir / relative).string(), 0, "",
                      std::string("cannot inspect: ") + std::strerror(errno));
  }
  if (S_ISLNK(st.st_mode))
    throw ConfigError((run_dir / relative).string(), 0, "",
                      "is a symbolic link; export reads only what lies inside the run folder and "
                      "follows no link, expected a file or folder");
  if (S_ISREG(st.st_mode)) return RunEntry::kFile;
  if (S_ISDIR(st.st_mode)) return RunEntry::kFolder;
  return RunEntry::kOther;
}

std::string ReadRunFile(const fs::path& run_dir, const fs::path& relative, uint64_t max_bytes) {
  const fs::path shown = run_dir / relative;
  std::string last;
  const UniqueFd dir(OpenParentFolder(run_dir, relative, &last));
  // O_NONBLOCK: a FIFO opens at once (and is refused below) instead of waiting for a writer
  const UniqueFd file(
      ::openat(dir.get(), last.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC));
  if (file.get() < 0) RefuseEntry(dir.get(), last, shown, errno, "a regular file");
  struct stat st {};
  if (fstat(file.get(), &st) != 0)
    throw ConfigError(shown.string(), 0, "",
                      std::string("cannot inspect: ") + std::strerror(errno));
  if (!S_ISREG(st.st_mode))
    throw ConfigError(shown.string(), 0, "",
                      "not a regular file (a folder, FIFO, socket or device); expected a file "
                      "written by `penumbra run`");
  const uint64_t size = static_cast<uint64_t>(st.st_size);
  if (size > max_bytes)
    throw ConfigError(shown.string(), 0, "",
                      std::to_string(size) + " bytes; expected at most " +
                          std::to_string(max_bytes) + " for this file");
  std::string bytes(static_cast<size_t>(size), '\0');
  size_t have = 0;
  while (have < bytes.size()) {
    const ssize_t n = ::read(file.get(), bytes.data() + have, bytes.size() - have);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0)
      throw ConfigError(shown.string(), 0, "", std::string("cannot read: ") + std::strerror(errno));
    if (n == 0) break;  // shortened while read: what is there
    have += static_cast<size_t>(n);
  }
  bytes.resize(have);
  return bytes;
}

}  // namespace penumbra
