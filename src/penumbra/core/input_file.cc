#include "penumbra/core/input_file.h"

#include <errno.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>

#include "penumbra/core/error.h"

namespace penumbra {

std::string FileKindName(mode_t st_mode) {
  if (S_ISREG(st_mode)) return "a regular file";
  if (S_ISDIR(st_mode)) return "a directory";
  if (S_ISFIFO(st_mode)) return "a FIFO";
  if (S_ISCHR(st_mode)) return "a character device";
  if (S_ISBLK(st_mode)) return "a block device";
  if (S_ISSOCK(st_mode)) return "a socket";
  if (S_ISLNK(st_mode)) return "a symbolic link";
  return "an unknown kind of file";
}

InputFile OpenInputFile(const std::filesystem::path& path, const std::string& what,
                        InputLinks links) {
  const std::string name = path.string();
  auto fail = [&](const std::string& problem) -> void { throw ConfigError(name, 0, "", problem); };
  auto refuse_kind = [&](mode_t mode) {
    if (S_ISDIR(mode)) fail(what + " is a directory; expected a regular file");
    if (S_ISLNK(mode))
      fail(what + " is a symbolic link; expected a regular file (links are not followed here)");
    fail(what + " is not a regular file (" + FileKindName(mode) + "); expected a regular file");
  };
  // O_NONBLOCK: a FIFO opens at once (and is refused below) instead of waiting for a writer;
  // O_NOCTTY: a terminal named as input does not become the controlling terminal
  int flags = O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC;
  if (links == InputLinks::kRefuse) flags |= O_NOFOLLOW;
  UniqueFd fd(::open(name.c_str(), flags));
  if (fd.get() < 0) {
    const int err = errno;
    if (err == ENOENT) {
      std::error_code ec;
      fail(what + " not found: " + std::filesystem::absolute(path, ec).lexically_normal().string() +
           "; expected an existing file");
    }
    // a socket cannot be opened (ENXIO), a link under O_NOFOLLOW gives ELOOP: name what it is
    struct stat st {};
    const int stat_result =
        links == InputLinks::kRefuse ? ::lstat(name.c_str(), &st) : ::stat(name.c_str(), &st);
    if (stat_result == 0 && !S_ISREG(st.st_mode)) refuse_kind(st.st_mode);
    fail("cannot read the " + what + ": " + std::strerror(err) + "; expected a readable file");
  }
  struct stat st {};
  if (::fstat(fd.get(), &st) != 0)
    fail("cannot read the " + what + ": " + std::strerror(errno) + "; expected a readable file");
  if (!S_ISREG(st.st_mode)) refuse_kind(st.st_mode);
  // reads of a regular file never block; clear the flag so that the descriptor behaves as
  // an ordinary one for whoever reads it
  const int status = ::fcntl(fd.get(), F_GETFL);
  if (status < 0 || ::fcntl(fd.get(), F_SETFL, status & ~O_NONBLOCK) != 0)
    fail("cannot read the " + what + ": " + std::strerror(errno) + "; expected a readable file");
  InputFile out;
  out.fd = std::move(fd);
  out.size = static_cast<uint64_t>(st.st_size);
  return out;
}

std::string ReadInputFile(const std::filesystem::path& path, const std::string& what,
                          size_t max_bytes, InputLinks links) {
  const std::string name = path.string();
  auto fail = [&](const std::string& problem) -> void { throw ConfigError(name, 0, "", problem); };
  const InputFile file = OpenInputFile(path, what, links);
  if (file.size > max_bytes) {
    fail(what + " is " + std::to_string(file.size) + " bytes; expected at most " +
         std::to_string(max_bytes) + " bytes");
  }
  std::string bytes(static_cast<size_t>(file.size), '\0');
  size_t done = 0;
  while (true) {
    // one byte past the size read at open: a file that grew is seen growing
    if (done == bytes.size()) {
      if (bytes.size() > max_bytes) {
        fail(what + " grew past " + std::to_string(max_bytes) +
             " bytes while it was read; expected at most " + std::to_string(max_bytes) + " bytes");
      }
      bytes.resize(std::min(max_bytes + 1, bytes.size() + 65536));
    }
    const ssize_t n = ::read(file.fd.get(), bytes.data() + done, bytes.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      fail("cannot read the " + what + ": " + std::strerror(errno) + "; expected a readable file");
    }
    if (n == 0) break;
    done += static_cast<size_t>(n);
  }
  bytes.resize(done);
  return bytes;
}

}  // namespace penumbra
