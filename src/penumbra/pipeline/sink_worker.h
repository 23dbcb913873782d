#pragma once
// the background thread of a sink (pipeline/sink.h): a sink's OnSnapshot, on the loop thread,
// posts the slow part of its work (rendering, ray tracing, formatting and writing files) here;
// tasks run one at a time in the order they were posted, so results stay deterministic.

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>

#include "penumbra/core/bounded_queue.h"

namespace penumbra {

/// one thread running posted tasks in order. errors: the first task that throws is reported
/// through the callback given to Start (e.g. LoopStart::report_error) and every later task is
/// skipped. Post/Finish are called from one thread (the loop's).
class SinkWorker {
 public:
  /// `capacity`: tasks waiting before Post blocks (back-pressure on the loop), >= 1.
  explicit SinkWorker(size_t capacity) : queue_(capacity) {}
  /// Finish() if it was not called (errors are then dropped).
  ~SinkWorker() { Finish(); }
  SinkWorker(const SinkWorker&) = delete;
  SinkWorker& operator=(const SinkWorker&) = delete;

  /// starts the thread; `report_error` receives the error of the first task that throws.
  void Start(std::function<void(std::exception_ptr)> report_error) {
    report_error_ = std::move(report_error);
    thread_ = std::thread([this] {
      while (std::optional<std::function<void()>> task = queue_.Pop()) {
        if (!failed_) {
          try {
            (*task)();
          } catch (...) {
            failed_ = true;
            if (report_error_) report_error_(std::current_exception());
          }
        }
        std::lock_guard<std::mutex> lock(done_mutex_);
        ++done_;
        done_cv_.notify_all();
      }
    });
  }

  /// queues `task` (after Start); blocks while `capacity` tasks wait. ignored after Finish.
  void Post(std::function<void()> task) {
    ++posted_;
    queue_.Push(std::move(task));
  }

  /// blocks until every task posted so far has run (or was skipped after an error); from the
  /// thread that posts. returns at once before Start or after Finish.
  void Drain() {
    if (!thread_.joinable() || finished_) return;
    std::unique_lock<std::mutex> lock(done_mutex_);
    done_cv_.wait(lock, [&] { return done_ >= posted_; });
  }

  /// runs every posted task (or skips it after an error), then ends the thread.
  void Finish() {
    if (finished_) return;
    finished_ = true;
    queue_.Close();
    if (thread_.joinable()) thread_.join();
  }

  /// a task threw (read after Finish).
  bool failed() const { return failed_; }

 private:
  BoundedQueue<std::function<void()>> queue_;
  std::function<void(std::exception_ptr)> report_error_;
  std::thread thread_;
  bool failed_ = false;
  bool finished_ = false;
  int64_t posted_ = 0;  // poster's thread
  std::mutex done_mutex_;
  std::condition_variable done_cv_;
  int64_t done_ = 0;  // guarded by done_mutex_
};

}  // namespace penumbra
