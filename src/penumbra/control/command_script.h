#pragma once
// command sources for controllers: a script of timed commands written in the world file,
// and a thread-safe queue that code on other threads (tests, the ROS cmd_vel / ZeroMQ
// bridges of the middleware) pushes commands into. any controller can own a
// CommandSource<C> of its own command type C and poll it at each control update.
//
// world-file form (the controller decides what a command holds):
//   commands:
//     - {t: 0.0, move_to: {xyz: [0.5, 0.0, 0.3], rpy_deg: [180, 0, 0]}}
//     - {t: 2.5, gripper: close}
// every item is a mapping with `t` (simulated time in s, >= 0, non-decreasing along the list)
// and the controller's own keys, which it reads through a ParamNode (unknown keys fail).
//
// timing: a command due at t takes effect at the first control update whose time is at
// least t - 1e-9 s. scripted commands come first, then queued ones in push order.
// determinism: the script is part of the world file, so it replays identically; queued
// commands are as deterministic as the times at which they are pushed (a command pushed
// with an explicit time before that time is reached applies at exactly that time).

#include <algorithm>
#include <atomic>
#include <functional>
#include <limits>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "penumbra/control/controller_params.h"
#include "penumbra/control/param_node.h"

namespace penumbra {

/// a command and the simulated time (s) at which it becomes due.
template <typename Command>
struct TimedCommand {
  double time_sec = 0;
  Command command{};
};

/// parses the script under `key` (absent: an empty script). `parse` reads one item's own
/// keys (everything but `t`) from the ParamNode of that item, path "<key>[i]"; keys it does
/// not read are errors.
/// @throws ConfigError for a key that is not a list, an item that is not a mapping, a
///         missing/negative `t`, times that go backwards, and whatever `parse` throws.
template <typename Command>
std::vector<TimedCommand<Command>> ParseCommandScript(
    ControllerParams& params, const std::string& key,
    const std::function<Command(ParamNode&)>& parse);

/// time tolerance (s) for "due": floating-point sums of timesteps land just short of round times.
inline constexpr double kCommandTimeToleranceSec = 1e-9;

/// scripted commands plus a thread-safe queue. Poll() runs on the physics thread;
/// Push/Set/ClearQueue may be called from any thread at any time.
template <typename Command>
class CommandSource {
 public:
  CommandSource() = default;
  /// `script` must be sorted by time (ParseCommandScript guarantees it).
  explicit CommandSource(std::vector<TimedCommand<Command>> script) : script_(std::move(script)) {}
  CommandSource(const CommandSource&) = delete;
  CommandSource& operator=(const CommandSource&) = delete;

  /// queues `command`, due at simulated time `at_time_sec` (the default: the next update).
  /// thread-safe.
  void Push(Command command, double at_time_sec = -std::numeric_limits<double>::infinity()) {
    std::lock_guard<std::mutex> lock(mutex_);
    queue_.push_back({at_time_sec, std::move(command)});
    pending_.store(true, std::memory_order_release);
  }
  /// replaces every queued command by `command`, due at the next update ("latest wins",
  /// e.g. for a stream of velocity commands). thread-safe.
  void Set(Command command) {
    std::lock_guard<std::mutex> lock(mutex_);
    queue_.clear();
    queue_.push_back({-std::numeric_limits<double>::infinity(), std::move(command)});
    pending_.store(true, std::memory_order_release);
  }
  /// drops every queued command (the script is kept). thread-safe.
  void ClearQueue() {
    std::lock_guard<std::mutex> lock(mutex_);
    queue_.clear();
    pending_.store(false, std::memory_order_release);
  }
  /// number of queued commands not yet applied. thread-safe.
  size_t queued() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return queue_.size();
  }

  /// calls apply(const Command&) for every command due at `time_sec`: scripted ones in
  /// order, then queued ones in push order; returns how many were applied. physics thread.
  template <typename F>
  int Poll(double time_sec, F&& apply) {
    int n = 0;
    const double now = time_sec + kCommandTimeToleranceSec;
    while (next_ < script_.size() && script_[next_].time_sec <= now) {
      apply(static_cast<const Command&>(script_[next_].command));
      ++next_;
      ++n;
    }
    if (!pending_.load(std::memory_order_acquire)) return n;
    // take the due commands out under the lock, apply them outside it
    due_.clear();
    {
      std::lock_guard<std::mutex> lock(mutex_);
      auto keep = queue_.begin();
      for (auto it = queue_.begin(); it != queue_.end(); ++it) {
        if (it->time_sec <= now) {
          due_.push_back(std::move(it->command));
        } else {
          if (keep != it) *keep = std::move(*it);
          ++keep;
        }
      }
      queue_.erase(keep, queue_.end());
      pending_.store(!queue_.empty(), std::memory_order_release);
    }
    for (const Command& c : due_) {
      apply(c);
      ++n;
    }
    return n;
  }

  /// the scripted commands, and how many of them have been applied.
  const std::vector<TimedCommand<Command>>& script() const { return script_; }
  size_t script_position() const { return next_; }
  /// starts the script over (the next Poll applies everything due again). physics thread.
  void Rewind() { next_ = 0; }

 private:
  std::vector<TimedCommand<Command>> script_;
  size_t next_ = 0;
  mutable std::mutex mutex_;
  std::vector<TimedCommand<Command>> queue_;
  std::vector<Command> due_;
  std::atomic<bool> pending_{false};
};

namespace command_script_detail {
/// the list under `key` as ParamNodes with path "<key>[i]" and their `t` values, checked.
std::vector<std::pair<double, ParamNode>> ReadTimedItems(ControllerParams& params,
                                                         const std::string& key);
}  // namespace command_script_detail

template <typename Command>
std::vector<TimedCommand<Command>> ParseCommandScript(
    ControllerParams& params, const std::string& key,
    const std::function<Command(ParamNode&)>& parse) {
  std::vector<TimedCommand<Command>> out;
  for (auto& [t, item] : command_script_detail::ReadTimedItems(params, key)) {
    Command c = parse(item);
    item.CheckNoUnknownKeys();
    out.push_back({t, std::move(c)});
  }
  return out;
}

}  // namespace penumbra
