#pragma once
// a fixed pool of worker threads running index-parallel loops. work items must be
// independent; results are then identical for any thread count.

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace penumbra {

/// persistent worker threads for ParallelFor. thread-compatible: one ParallelFor at a time.
class ThreadPool {
 public:
  /// @param num_threads total threads including the caller; 0 = hardware concurrency.
  /// @throws std::system_error when a thread cannot be started (the threads already started
  ///         are stopped and joined first), std::bad_alloc.
  explicit ThreadPool(int num_threads = 0);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  /// calls fn(i) for every i in [0, count), spread over the pool; blocks until all are done.
  /// the first exception thrown by fn is rethrown here after the loop drains.
  void ParallelFor(int64_t count, const std::function<void(int64_t)>& fn);

  /// threads used, including the calling thread.
  int num_threads() const { return static_cast<int>(workers_.size()) + 1; }

 private:
  void WorkerLoop();
  void Stop();
  void RunItems();

  std::vector<std::thread> workers_;
  std::mutex mu_;
  std::condition_variable cv_start_, cv_done_;
  const std::function<void(int64_t)>* fn_ = nullptr;
  int64_t count_ = 0;
  std::atomic<int64_t> next_{0};
  int active_ = 0;
  uint64_t generation_ = 0;
  bool stop_ = false;
  std::exception_ptr error_;
};

/// calls fn(i) for every i in [0, count): over `pool` when it is given (ThreadPool::ParallelFor),
/// else in index order on the calling thread.
template <typename Fn>
void ParallelForOrSerial(ThreadPool* pool, int64_t count, const Fn& fn) {
  if (pool != nullptr) {
    pool->ParallelFor(count, fn);
  } else {
    for (int64_t i = 0; i < count; ++i) fn(i);
  }
}

}  // namespace penumbra
