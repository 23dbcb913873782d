#include "penumbra/rollout/rollout_args.h"

#include <errno.h>
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <thread>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

std::string FormatDouble(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  return std::to_string(v);
}

std::string KindOf(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "an unknown kind of file";
}

// closes a file descriptor when it goes out of scope
class Fd {
 public:
  explicit Fd(int fd) : fd_(fd) {}
  ~Fd() {
    if (fd_ >= 0) ::close(fd_);
  }
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  int get() const { return fd_; }

 private:
  int fd_;
};

}  // namespace

int64_t MaxRolloutThreads() {
  const int64_t hw = std::max<int64_t>(1, std::thread::hardware_concurrency());
  return hw * kRolloutThreadsPerHardwareThread;
}

size_t RolloutMemoryCap() {
  const long pages = ::sysconf(_SC_PHYS_PAGES);
  const long page = ::sysconf(_SC_PAGE_SIZE);
  size_t cap = pages > 0 && page > 0 ? static_cast<size_t>(pages) * static_cast<size_t>(page)
                                     : size_t{4} << 30;
  rlimit as{};
  if (::getrlimit(RLIMIT_AS, &as) == 0 && as.rlim_cur != RLIM_INFINITY) {
    // the room left under the limit: its size less the address space in use (statm, pages)
    size_t used = 0;
    if (FILE* f = std::fopen("/proc/self/statm", "r")) {
      unsigned long long used_pages = 0;
      if (std::fscanf(f, "%llu", &used_pages) == 1 && page > 0)
        used = static_cast<size_t>(used_pages) * static_cast<size_t>(page);
      std::fclose(f);
    }
    const size_t limit = static_cast<size_t>(as.rlim_cur);
    cap = std::min(cap, limit > used ? limit - used : 0);
  }
  return cap;
}

void ValidateRolloutCounts(int64_t num_copies, int64_t num_threads, int64_t substeps,
                           int64_t max_threads) {
  if (num_copies < 1 || num_copies > kMaxRolloutCopies) {
    throw ConfigError("", 0, "num_copies",
                      "got " + std::to_string(num_copies) + "; expected an integer in [1, " +
                          std::to_string(kMaxRolloutCopies) + "]");
  }
  if (num_threads < 0 || num_threads > max_threads) {
    throw ConfigError("", 0, "num_threads",
                      "got " + std::to_string(num_threads) +
                          "; expected 0 (one per hardware thread) or an integer in [1, " +
                          std::to_string(max_threads) + "] (" +
                          std::to_string(kRolloutThreadsPerHardwareThread) +
                          " x the hardware threads)");
  }
  if (substeps < 1 || substeps > kMaxRolloutSubsteps) {
    throw ConfigError("", 0, "substeps",
                      "got " + std::to_string(substeps) + "; expected an integer in [1, " +
                          std::to_string(kMaxRolloutSubsteps) + "]");
  }
}

void CheckRolloutMemory(int64_t num_copies, size_t bytes_per_copy, size_t cap_bytes) {
  const size_t per = std::max<size_t>(bytes_per_copy, 1);
  const size_t max_copies = cap_bytes / per;
  if (num_copies < 0 || static_cast<uint64_t>(num_copies) > max_copies) {
    throw ConfigError(
        "", 0, "num_copies",
        "got " + std::to_string(num_copies) + " copies of " + std::to_string(per) +
            " bytes each; expected at most " + std::to_string(max_copies) +
            " copies of this model (the copies may take " + std::to_string(cap_bytes) +
            " bytes: the physical memory, or the room left under the address-space limit)");
  }
}

void CheckFiniteValues(const double* values, size_t count, size_t cols, const std::string& name) {
  for (size_t i = 0; i < count; ++i) {
    if (std::isfinite(values[i])) continue;
    const std::string index =
        cols > 1 ? std::to_string(i / cols) + ", " + std::to_string(i % cols) : std::to_string(i);
    throw ConfigError("", 0, name + "[" + index + "]",
                      "got " + FormatDouble(values[i]) + "; expected a finite number");
  }
}

std::string ReadRolloutModelFile(const std::string& path, size_t max_bytes) {
  auto fail = [&](const std::string& problem) {
    throw ConfigError(path, 0, "model_path", problem);
  };
  // open() would stop at a NUL and open another file
  if (path.empty() || path.find('\0') != std::string::npos)
    fail("model path is empty or holds a NUL byte; expected a file name");
  Fd fd(::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC));
  if (fd.get() < 0) {
    const int err = errno;
    if (err == ENOENT) fail("model file not found; expected an MJCF file");
    fail(std::string("cannot read the model file: ") + std::strerror(err));
  }
  struct stat st {};
  if (::fstat(fd.get(), &st) != 0)
    fail(std::string("cannot read the model file: ") + std::strerror(errno));
  if (!S_ISREG(st.st_mode))
    fail("model file is not a regular file (" + KindOf(st.st_mode) +
         "); expected a regular MJCF file");
  const auto size = static_cast<uint64_t>(st.st_size);
  if (size > max_bytes) {
    fail("model file is " + std::to_string(size) + " bytes; expected at most " +
         std::to_string(max_bytes) + " bytes");
  }
  std::string bytes(static_cast<size_t>(size) + 1, '\0');
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::read(fd.get(), bytes.data() + done, bytes.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      fail(std::string("cannot read the model file: ") + std::strerror(errno));
    }
    if (n == 0) break;
    done += static_cast<size_t>(n);
  }
  if (done > size) fail("model file grew while it was read; expected a file that does not change");
  bytes.resize(done);
  return bytes;
}

}  // namespace penumbra
