#include "penumbra/core/output_path_policy.h"

#include <errno.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <functional>

namespace penumbra {
namespace {

std::string Expected(std::string_view ext) {
  return "expected a new file name ending in " + std::string(ext) +
         ", relative to the run's output folder (e.g. 'live" + std::string(ext) +
         "' or 'logs/live" + std::string(ext) + "' with an existing folder logs)";
}

// what is at `name` in the folder `dirfd`, without following a link
std::string WhatIsThere(int dirfd, const std::string& name) {
  struct stat st;
  if (::fstatat(dirfd, name.c_str(), &st, AT_SYMLINK_NOFOLLOW) != 0) return "";
  if (S_ISLNK(st.st_mode)) return "a symbolic link";
  if (S_ISDIR(st.st_mode)) return "a folder";
  if (S_ISREG(st.st_mode)) return "a file";
  return "a special file";
}

// the path rules shared by the write and the read side; `fail` throws
std::vector<std::string> SplitClientPath(const std::string& path,
                                         std::string_view required_extension, bool reading,
                                         const std::function<void(const std::string&)>& fail) {
  if (path.empty()) fail("is empty");
  if (path.size() > kMaxClientPathBytes)
    fail("is " + std::to_string(path.size()) + " bytes long, more than " +
         std::to_string(kMaxClientPathBytes));
  for (const char c : path) {
    const auto b = static_cast<unsigned char>(c);
    if (b < 0x20 || b == 0x7f) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02x", b);
      fail(std::string("holds the control character ") + hex);
    }
  }
  if (path.front() == '/')
    fail(reading
             ? "is absolute (starts with '/'); only files inside the folder are read"
             : "is absolute (starts with '/'); only paths inside the output folder are written");
  std::vector<std::string> parts;
  size_t start = 0;
  for (;;) {
    const size_t slash = path.find('/', start);
    parts.push_back(
        path.substr(start, slash == std::string::npos ? std::string::npos : slash - start));
    if (slash == std::string::npos) break;
    start = slash + 1;
  }
  for (const std::string& p : parts) {
    if (p == "..")
      fail(reading ? "has a '..' component (it would leave the folder)"
                   : "has a '..' component (it would leave the output folder)");
    if (p.empty()) fail("has an empty component ('//' or a trailing '/')");
    if (p == ".") fail("has a '.' component");
  }
  const std::string& name = parts.back();
  if (name.size() < required_extension.size() ||
      name.compare(name.size() - required_extension.size(), std::string::npos,
                   required_extension) != 0)
    fail("does not end in " + std::string(required_extension));
  if (name.size() == required_extension.size())
    fail("has no name before " + std::string(required_extension));
  return parts;
}

}  // namespace

UniqueFd& UniqueFd::operator=(UniqueFd&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = other.release();
  }
  return *this;
}

UniqueFd::~UniqueFd() {
  if (fd_ >= 0) ::close(fd_);
}

OutputPathError::OutputPathError(const std::string& client_path, const std::string& rule,
                                 std::string_view required_extension)
    : Error("output path '" + SanitizeForMessage(client_path, 300) + "': " + rule + "; " +
            Expected(required_extension)),
      client_path_(client_path),
      rule_(rule) {}

UniqueFd OpenFoldersNoFollow(UniqueFd dir, const std::vector<std::string>& parts,
                             const std::function<void(int, size_t, int)>& refuse) {
  for (size_t i = 0; i + 1 < parts.size(); ++i) {
    UniqueFd next(
        ::openat(dir.get(), parts[i].c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC));
    if (next.get() < 0) {
      refuse(dir.get(), i, errno);
      throw Error("folder '" + SanitizeForMessage(parts[i], 300) + "' cannot be opened");
    }
    dir = std::move(next);
  }
  return dir;
}

namespace {

// opens the folder that holds the last of `parts` (checked components below `root`): `root` as
// the user named it (a link there is the user's own choice), then each folder below it relative
// to the one above with O_NOFOLLOW, so no link is followed; `fail` (which throws) gets the rule
// broken. `root_name` names root in messages, `missing_hint` follows "does not exist".
template <typename Fail>
UniqueFd OpenFolderOf(const std::filesystem::path& root, const std::vector<std::string>& parts,
                      const std::string& root_name, const std::string& missing_hint, Fail fail) {
  UniqueFd dir(::open(root.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (dir.get() < 0) fail(root_name + " cannot be opened: " + std::strerror(errno));
  return OpenFoldersNoFollow(std::move(dir), parts, [&](int parent_fd, size_t i, int err) {
    std::string walked;
    for (size_t k = 0; k <= i; ++k) walked += (k ? "/" : "") + parts[k];
    const std::string what = WhatIsThere(parent_fd, parts[i]);
    const std::string quoted = "'" + SanitizeForMessage(walked, 300) + "'";
    if (what == "a symbolic link") fail(quoted + " is a symbolic link; links are never followed");
    if (!what.empty() && what != "a folder") fail(quoted + " is " + what + ", not a folder");
    if (err == ENOENT) fail("the folder " + quoted + " does not exist" + missing_hint);
    fail("the folder " + quoted + " cannot be opened: " + std::strerror(err));
  });
}

}  // namespace

std::vector<std::string> CheckClientPath(std::string_view client_path,
                                         std::string_view required_extension) {
  const std::string path(client_path);
  return SplitClientPath(path, required_extension, false, [&](const std::string& rule) {
    throw OutputPathError(path, rule, required_extension);
  });
}

NewOutputFile OpenNewFileInside(const std::filesystem::path& root, std::string_view client_path,
                                std::string_view required_extension) {
  const std::string path(client_path);
  const std::vector<std::string> parts = CheckClientPath(client_path, required_extension);
  auto fail = [&](const std::string& rule) {
    throw OutputPathError(path, rule, required_extension);
  };
  UniqueFd dir = OpenFolderOf(root, parts, "the run's output folder",
                              "; only existing folders are written into", fail);
  const std::string& name = parts.back();
  UniqueFd fd(::openat(dir.get(), name.c_str(),
                       O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644));
  if (fd.get() < 0) {
    const int err = errno;
    if (err == EEXIST) {
      const std::string what = WhatIsThere(dir.get(), name);
      fail("already exists" + (what.empty() ? std::string() : " (" + what + ")") +
           "; files are never overwritten and links never followed: choose a new name");
    }
    fail(std::string("cannot be created: ") + std::strerror(err));
  }
  NewOutputFile out;
  out.fd = std::move(fd);
  out.folder = std::move(dir);
  out.name = name;
  out.path = root / path;
  out.relative = path;
  return out;
}

InputPathError::InputPathError(const std::string& client_path, const std::string& rule,
                               std::string_view required_extension, std::string_view folder_name)
    : Error("file '" + SanitizeForMessage(client_path, 300) + "': " + rule +
            "; expected an existing file ending in " + std::string(required_extension) +
            ", named relative to " + std::string(folder_name) + " (no '..', no symbolic link)"),
      client_path_(client_path),
      rule_(rule) {}

ExistingInputFile ReadExistingFileInside(const std::filesystem::path& root,
                                         std::string_view client_path,
                                         std::string_view required_extension, size_t max_bytes,
                                         std::string_view folder_name) {
  const std::string path(client_path);
  auto fail = [&](const std::string& rule) {
    throw InputPathError(path, rule, required_extension, folder_name);
  };
  const std::vector<std::string> parts = SplitClientPath(path, required_extension, true, fail);
  UniqueFd dir = OpenFolderOf(root, parts, "the folder", "", fail);
  // the file: never through a link, and without blocking on a FIFO
  const std::string& name = parts.back();
  UniqueFd fd(
      ::openat(dir.get(), name.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_NOCTTY | O_CLOEXEC));
  if (fd.get() < 0) {
    const int err = errno;
    const std::string what = WhatIsThere(dir.get(), name);
    if (what == "a symbolic link") fail("is a symbolic link; links are never followed");
    if (err == ENOENT) fail("does not exist");
    fail(std::string("cannot be opened: ") + std::strerror(err));
  }
  struct stat st;
  if (::fstat(fd.get(), &st) != 0) fail(std::string("cannot be read: ") + std::strerror(errno));
  if (S_ISDIR(st.st_mode)) fail("is a folder, not a file");
  if (!S_ISREG(st.st_mode)) fail("is a special file (FIFO, device or socket), not a regular file");
  if (static_cast<uint64_t>(st.st_size) > max_bytes)
    fail("is " + std::to_string(st.st_size) + " bytes long, more than " +
         std::to_string(max_bytes));
  // read at most max_bytes + 1: a file that grew since fstat is refused, not read on
  ExistingInputFile out;
  out.text.resize(static_cast<size_t>(st.st_size));
  size_t got = 0;
  for (;;) {
    if (got == out.text.size()) {
      if (out.text.size() > max_bytes) break;
      out.text.resize(std::min(max_bytes + 1, out.text.size() + 4096));
    }
    const ssize_t n = ::read(fd.get(), out.text.data() + got, out.text.size() - got);
    if (n < 0) {
      if (errno == EINTR) continue;
      fail(std::string("cannot be read: ") + std::strerror(errno));
    }
    if (n == 0) break;
    got += static_cast<size_t>(n);
  }
  if (got > max_bytes) fail("is more than " + std::to_string(max_bytes) + " bytes long");
  out.text.resize(got);
  out.path = root / path;
  out.relative = path;
  return out;
}

}  // namespace penumbra
