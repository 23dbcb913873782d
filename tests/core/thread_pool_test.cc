// tests of core/thread_pool.h: ParallelFor visits every index once, and a pool whose threads
// cannot all start (here: an address-space limit leaves room for one thread stack) throws
// std::system_error with the threads it did start joined, instead of destroying joinable
// threads (std::terminate) or leaving them waiting on a destroyed pool.

#include "penumbra/core/thread_pool.h"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <system_error>
#include <vector>

namespace penumbra {
namespace {

TEST(ThreadPool, ParallelForVisitsEveryIndexOnce) {
  ThreadPool pool(3);
  EXPECT_EQ(pool.num_threads(), 3);
  std::vector<std::atomic<int>> seen(1000);
  pool.ParallelFor(1000, [&](int64_t i) { seen[i].fetch_add(1); });
  for (const auto& s : seen) EXPECT_EQ(s.load(), 1);
}

// the address space in use (bytes), from /proc/self/statm
size_t AddressSpaceInUse() {
  unsigned long long pages = 0;
  if (FILE* f = std::fopen("/proc/self/statm", "r")) {
    if (std::fscanf(f, "%llu", &pages) != 1) pages = 0;
    std::fclose(f);
  }
  return static_cast<size_t>(pages) * static_cast<size_t>(::sysconf(_SC_PAGE_SIZE));
}

// in a child: a 64-thread pool under an address-space limit that leaves room for about one
// more 8 MiB thread stack; exits 0 when the pool threw and a one-thread pool then works
// (SIGALRM after 30 s: the pool deadlocked)
[[noreturn]] void StartPoolUnderLimit() {
  ::alarm(30);
  const rlim_t limit = AddressSpaceInUse() + (size_t{12} << 20);
  const rlimit rl{limit, limit};
  if (::setrlimit(RLIMIT_AS, &rl) != 0) _exit(3);
  try {
    ThreadPool pool(64);
    _exit(2);  // all 63 threads started: the limit did not bite
  } catch (const std::system_error&) {
  }
  ThreadPool one(1);
  int sum = 0;
  one.ParallelFor(4, [&](int64_t i) { sum += static_cast<int>(i); });
  _exit(sum == 6 ? 0 : 4);
}

TEST(ThreadPoolDeathTest, ThreadsThatCannotStartThrowAndTheStartedOnesAreJoined) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(StartPoolUnderLimit(), ::testing::ExitedWithCode(0), "");
}

}  // namespace
}  // namespace penumbra
