#pragma once
// SIGINT / SIGTERM while a long verb runs (`run`, `replay`, `view`, `benchmark`, `export`):
// the first signal sets the stop request the verb polls (its run stops at the next physics
// step boundary and writes its outputs) and prints a message; a second exits at once with
// 128 + signal. async-signal-safe: a lock-free atomic, write(2) and _exit(2) only.

#include <signal.h>

#include <atomic>

namespace penumbra {

/// the stop request StopSignals sets: 0, or the number of the first signal.
std::atomic<int>& StopSignal();

/// the message of a run's first signal ("stopping at the next physics step ...").
extern const char kRunStopMessage[];
/// the message of an export's first signal ("stopping the export ...").
extern const char kExportStopMessage[];

/// resets StopSignal() to 0 and installs the handler for SIGINT and SIGTERM while it lives;
/// `message` (static storage) is written to stderr on the first signal.
class StopSignals {
 public:
  explicit StopSignals(const char* message = kRunStopMessage);
  ~StopSignals();
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

 private:
  struct sigaction old_int_ = {}, old_term_ = {};
};

}  // namespace penumbra
