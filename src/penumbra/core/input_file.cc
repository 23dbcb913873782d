#include "penumbra/core/input_file.h"

#include <errno.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>

#include "penumbra/core/error.h"

namespace penumbra {

namespace {

// closes a file descriptor when it goes out of scope
class InputFd {
 public:
  explicit InputFd(int fd) : fd_(fd) {}
  ~InputFd() {
    if (fd_ >= 0) ::close(fd_);
  }
  InputFd(const InputFd&) = delete;
  InputFd& operator=(const InputFd&) = delete;
  int get() const { return fd_; }

 private:
  int fd_;
};

}  // namespace

std::string ReadInputFile(const std::filesystem::path& path, const std::string& what,
                          size_t max_bytes) {
  const std::string name = path.string();
  auto fail = [&](const std::string& problem) -> void { throw ConfigError(name, 0, "", problem); };
  InputFd fd(::open(name.c_str(), O_RDONLY | O_CLOEXEC));
  if (fd.get() < 0) {
    const int err = errno;
    if (err == ENOENT) {
      std::error_code ec;
      fail(what + " not found: " + std::filesystem::absolute(path, ec).lexically_normal().string() +
           "; expected an existing file");
    }
    fail("cannot read the " + what + ": " + std::strerror(err) + "; expected a readable file");
  }
  struct stat st {};
  if (::fstat(fd.get(), &st) != 0)
    fail("cannot read the " + what + ": " + std::strerror(errno) + "; expected a readable file");
  if (!S_ISREG(st.st_mode)) fail(what + " is not a regular file; expected a file");
  const auto size = static_cast<unsigned long long>(st.st_size);
  if (size > max_bytes) {
    fail(what + " is " + std::to_string(size) + " bytes; expected at most " +
         std::to_string(max_bytes) + " bytes");
  }
  std::string bytes(static_cast<size_t>(size), '\0');
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
    const ssize_t n = ::read(fd.get(), bytes.data() + done, bytes.size() - done);
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
