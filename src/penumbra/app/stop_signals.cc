#include "penumbra/app/stop_signals.h"

#include <unistd.h>

#include <cstring>

namespace penumbra {
namespace {

std::atomic<int> g_stop_signal{0};
static_assert(std::atomic<int>::is_always_lock_free);

// the message of the first signal (set before the handler is installed)
const char* g_stop_message = kRunStopMessage;

extern "C" void OnStopSignal(int sig) {
  int expected = 0;
  if (!g_stop_signal.compare_exchange_strong(expected, sig)) _exit(128 + sig);
  const ssize_t ignored = write(STDERR_FILENO, g_stop_message, strlen(g_stop_message));
  (void)ignored;
}

}  // namespace

const char kRunStopMessage[] =
    "\npenumbra: stopping at the next physics step and writing the outputs "
    "(signal again to exit at once)\n";
const char kExportStopMessage[] =
    "\npenumbra: stopping the export and removing its partial output "
    "(signal again to exit at once)\n";

std::atomic<int>& StopSignal() { return g_stop_signal; }

StopSignals::StopSignals(const char* message) {
  g_stop_signal.store(0);
  g_stop_message = message;
  struct sigaction sa = {};
  sa.sa_handler = OnStopSignal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, &old_int_);
  sigaction(SIGTERM, &sa, &old_term_);
}

StopSignals::~StopSignals() {
  sigaction(SIGINT, &old_int_, nullptr);
  sigaction(SIGTERM, &old_term_, nullptr);
}

}  // namespace penumbra
