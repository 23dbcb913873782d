#pragma once
// the first error of a run that has several threads (loop, render, writers): every thread
// records what went wrong, the run reports the one that came first.

#include <exception>
#include <mutex>
#include <string>

namespace penumbra {

/// first-wins holder of an exception; thread-safe.
class FirstError {
 public:
  /// keeps `e` if no error was recorded before (a null `e` is ignored); true if it was kept.
  bool Record(std::exception_ptr e) {
    if (!e) return false;
    std::lock_guard<std::mutex> lock(mu_);
    if (first_) return false;
    first_ = e;
    return true;
  }
  /// the first error recorded, or null.
  std::exception_ptr get() const {
    std::lock_guard<std::mutex> lock(mu_);
    return first_;
  }

 private:
  mutable std::mutex mu_;
  std::exception_ptr first_;
};

/// the message of an exception (what()), "unknown error" for a non-std exception.
std::string ErrorMessage(std::exception_ptr e);

}  // namespace penumbra
