#include "penumbra/core/output_path_policy.h"

#include <errno.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>

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

std::vector<std::string> CheckClientPath(std::string_view client_path,
                                         std::string_view required_extension) {
  const std::string path(client_path);
  auto fail = [&](const std::string& rule) {
    throw OutputPathError(path, rule, required_extension);
  };
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
    fail("is absolute (starts with '/'); only paths inside the output folder are written");
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
    if (p == "..") fail("has a '..' component (it would leave the output folder)");
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

NewOutputFile OpenNewFileInside(const std::filesystem::path& root, std::string_view client_path,
                                std::string_view required_extension) {
  const std::string path(client_path);
  const std::vector<std::string> parts = CheckClientPath(client_path, required_extension);
  auto fail = [&](const std::string& rule) {
    throw OutputPathError(path, rule, required_extension);
  };
  // the output folder as the user named it (a link there is the user's own choice)
  UniqueFd dir(::open(root.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (dir.get() < 0)
    fail(std::string("the run's output folder cannot be opened: ") + std::strerror(errno));
  // each folder below it: opened relative to the one above, never through a link
  std::string walked;
  for (size_t i = 0; i + 1 < parts.size(); ++i) {
    walked += (walked.empty() ? "" : "/") + parts[i];
    UniqueFd next(
        ::openat(dir.get(), parts[i].c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC));
    if (next.get() < 0) {
      const int err = errno;
      const std::string what = WhatIsThere(dir.get(), parts[i]);
      const std::string quoted = "'" + SanitizeForMessage(walked, 300) + "'";
      if (what == "a symbolic link") fail(quoted + " is a symbolic link; links are never followed");
      if (!what.empty() && what != "a folder") fail(quoted + " is " + what + ", not a folder");
      if (err == ENOENT)
        fail("the folder " + quoted + " does not exist; only existing folders are written into");
      fail("the folder " + quoted + " cannot be opened: " + std::strerror(err));
    }
    dir = std::move(next);
  }
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

}  // namespace penumbra
