#include "penumbra/rollout/rollout_args.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <thread>

#include "penumbra/core/error.h"
#include "penumbra/core/input_file.h"

namespace penumbra {
namespace {

std::string FormatDouble(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  return std::to_string(v);
}

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
  // open() would stop at a NUL and open another file
  if (path.empty() || path.find('\0') != std::string::npos)
    throw ConfigError(path, 0, "model_path",
                      "model path is empty or holds a NUL byte; expected a file name");
  try {
    return ReadInputFile(path, "model file", max_bytes);
  } catch (const ConfigError& e) {
    throw ConfigError(path, 0, "model_path", e.problem());
  }
}

}  // namespace penumbra
