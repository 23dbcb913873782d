#pragma once
// bounds of everything a caller (the Python module _penumbra_rollout, a C++ program, a fuzzer)
// passes to a BatchStepper, checked before anything is allocated or started: thread, copy and
// substep counts, the memory the copies would take, finite inputs, and the model file (a
// regular file of bounded size, opened without ever blocking). every check throws ConfigError
// naming the argument (its key) and the bound; the Python module raises ValueError for it.

#include <cstddef>
#include <cstdint>
#include <string>

namespace penumbra {

/// threads per hardware thread a stepper may use at most (num_threads <= this x hardware
/// threads).
inline constexpr int64_t kRolloutThreadsPerHardwareThread = 4;
/// most mj_step calls per BatchStepper::Step and copy (substeps); 1000 substeps of the bundled
/// 2 ms timestep are 2 s of simulated time per policy step.
inline constexpr int64_t kMaxRolloutSubsteps = 1000;
/// most copies a stepper may hold, whatever the model (a smaller bound follows from memory).
inline constexpr int64_t kMaxRolloutCopies = int64_t{1} << 20;
/// largest model (MJCF) file a stepper reads: 64 MiB.
inline constexpr size_t kMaxRolloutModelFileBytes = size_t{64} << 20;

/// the most threads a stepper may use: kRolloutThreadsPerHardwareThread x the hardware threads
/// (std::thread::hardware_concurrency, at least 1).
int64_t MaxRolloutThreads();

/// the memory the copies of one stepper may take together (bytes): the machine's physical
/// memory (sysconf), or under an address-space limit (RLIMIT_AS) the room left in it (the limit
/// less the address space in use, /proc/self/statm) when that is less. the copies' size counts
/// each copy's whole mjData stack, most of which MuJoCo only touches in crowded contact.
size_t RolloutMemoryCap();

/// checks the counts of a BatchStepper as the caller passed them (64-bit, before narrowing):
/// 1 <= num_copies <= kMaxRolloutCopies, 0 (hardware threads) <= num_threads <= max_threads,
/// 1 <= substeps <= kMaxRolloutSubsteps.
/// @throws ConfigError("", 0, "num_copies" | "num_threads" | "substeps", "got N; expected ...")
///         naming the bound.
void ValidateRolloutCounts(int64_t num_copies, int64_t num_threads, int64_t substeps,
                           int64_t max_threads = MaxRolloutThreads());

/// checks that num_copies copies of bytes_per_copy bytes each fit in cap_bytes.
/// @throws ConfigError("", 0, "num_copies", "got N copies of B bytes each (T bytes); expected at
///         most M copies of this model (the cap ...)").
void CheckRolloutMemory(int64_t num_copies, size_t bytes_per_copy,
                        size_t cap_bytes = RolloutMemoryCap());

/// checks that every one of `count` values is finite (no NaN, no infinity). `cols` > 1 reads
/// the values as rows of `cols` (the index is named "name[row, col]"), else "name[i]".
/// @throws ConfigError("", 0, "name[row, col]", "got nan; expected a finite number").
void CheckFiniteValues(const double* values, size_t count, size_t cols, const std::string& name);

/// the whole of the model file `path`, read by core/input_file.h's ReadInputFile (opened with
/// O_NONBLOCK, so a FIFO opens at once instead of waiting for a writer; checked with fstat on
/// the open descriptor to be a regular file of at most max_bytes).
/// @throws ConfigError(path, 0, "model_path", problem) with problem "model path is empty or
///         holds a NUL byte; expected a file name" or ReadInputFile's: "model file not found:
///         <absolute path>; expected an existing file", "model file is a directory; expected a
///         regular file", "model file is not a regular file (a FIFO); expected a regular file"
///         (likewise a character or block device, a socket), "model file is N bytes; expected
///         at most M bytes" or "cannot read the model file: <reason>; expected a readable file".
std::string ReadRolloutModelFile(const std::string& path,
                                 size_t max_bytes = kMaxRolloutModelFileBytes);

}  // namespace penumbra
