#include "penumbra/command/run_control.h"

#include <fmt/format.h>

#include <algorithm>

#include "penumbra/command/command_error.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

constexpr auto kPollInterval = std::chrono::milliseconds(50);

nlohmann::json ErrorOnly(const CommandError& e) { return {{"ok", false}, {"error", e.ToJson()}}; }

}  // namespace

RunControl::RunControl(Simulation* sim, RunControlOptions options) : sim_(sim), options_(options) {
  if (!(options_.realtime_factor >= 0))
    throw Error(fmt::format("realtime factor {} must be >= 0", options_.realtime_factor));
  factor_.store(options_.realtime_factor);
  paused_.store(options_.start_paused);
}

RunControl::~RunControl() = default;

void RunControl::AddDrain(std::function<void()> drain) { drains_.push_back(std::move(drain)); }

void RunControl::RunDrains() {
  for (auto& d : drains_) d();
}

void RunControl::Submit(Action action, Done done) {
  {
    std::lock_guard<std::mutex> lock(mu_);
    if (!ended_.load()) {
      queue_.push_back(Work{std::move(action), 0, false, std::move(done)});
      has_work_.store(true, std::memory_order_release);
      cv_.notify_all();
      return;
    }
  }
  done(ErrorOnly(CommandError(command_code::kRunEnded, "", "the run has ended")));
}

void RunControl::RequestSteps(int64_t n, bool with_state, Done done) {
  {
    std::lock_guard<std::mutex> lock(mu_);
    if (!ended_.load()) {
      queue_.push_back(Work{nullptr, std::max<int64_t>(1, n), with_state, std::move(done)});
      has_work_.store(true, std::memory_order_release);
      cv_.notify_all();
      return;
    }
  }
  done(ErrorOnly(CommandError(command_code::kRunEnded, "", "the run has ended")));
}

void RunControl::RequestStop() {
  std::lock_guard<std::mutex> lock(mu_);
  stop_.store(1);
  cv_.notify_all();
}

void RunControl::SetRealtimeFactor(double factor) {
  factor_.store(std::max(0.0, factor));
  factor_changed_.store(true);
}

void RunControl::SetPaused(bool paused, Done done) {
  Submit(
      [this, paused](Simulation& sim) {
        if (paused && !paused_.load()) RunDrains();
        paused_.store(paused);
        anchored_ = false;
        return nlohmann::json{
            {"step", sim.step_count()}, {"time_sec", sim.time()}, {"paused", paused}};
      },
      std::move(done));
}

void RunControl::Reanchor(const Simulation& sim) {
  anchored_ = true;
  anchor_wall_ = Clock::now();
  anchor_step_ = sim.step_count();
}

nlohmann::json RunControl::StateJson(const Simulation& sim) const {
  const SimState s = sim.GetState();
  const WorldSnapshot snap = sim.Snapshot(Simulation::SnapshotContent::kFull);
  return {{"step", s.step},
          {"time_sec", s.time_sec},
          {"qpos", s.qpos},
          {"qvel", s.qvel},
          {"act", s.act},
          {"ctrl", s.ctrl},
          {"mocap_pos", s.mocap_pos},
          {"mocap_quat", s.mocap_quat},
          {"sensordata", snap.sensordata},
          {"paused", paused_.load()}};
}

void RunControl::CompleteSteps(Simulation& sim, bool ended) {
  RunDrains();
  nlohmann::json r = {
      {"ok", true}, {"step", sim.step_count()}, {"time_sec", sim.time()}, {"ended", ended}};
  if (active_->with_state) {
    const nlohmann::json state = StateJson(sim);
    for (auto& [k, v] : state.items()) r[k] = v;
  }
  Done done = std::move(active_->done);
  active_.reset();
  remaining_ = 0;
  done(std::move(r));
}

bool RunControl::BeforeStep(Simulation& sim) {
  if (options_.external_stop && options_.external_stop->load() != 0) stop_.store(1);
  boundary_step_.store(sim.step_count(), std::memory_order_relaxed);
  boundary_time_.store(sim.time(), std::memory_order_relaxed);
  // running free with nothing to do and no pacing: step at once
  if (!active_ && !paused_.load(std::memory_order_relaxed) &&
      !has_work_.load(std::memory_order_acquire) && factor_.load() == 0 && stop_.load() == 0)
    return true;
  return Gate(sim, false);
}

bool RunControl::Gate(Simulation& sim, bool at_start) {
  for (;;) {
    if (options_.external_stop && options_.external_stop->load() != 0) stop_.store(1);
    // 1. a step request whose steps are all taken completes
    if (!at_start && active_ && remaining_ == 0) CompleteSteps(sim, false);
    if (stop_.load() != 0) return false;
    if (active_) {
      // at the start the step request's first snapshot (step 0) comes before its steps
      if (!at_start) --remaining_;
      return true;
    }
    // 2. queued work, in arrival order
    std::optional<Work> work;
    {
      std::lock_guard<std::mutex> lock(mu_);
      if (!queue_.empty()) {
        work = std::move(queue_.front());
        queue_.pop_front();
      }
      has_work_.store(!queue_.empty(), std::memory_order_release);
    }
    if (work) {
      if (work->steps > 0) {
        if (!paused_.load()) {
          work->done(ErrorOnly(CommandError(
              command_code::kConflict, "",
              "the run is not paused: `step` works in lockstep mode (--lockstep) or after "
              "`pause`")));
          continue;
        }
        remaining_ = work->steps;
        active_ = std::move(work);
        continue;
      }
      nlohmann::json reply;
      try {
        nlohmann::json fields = work->action(sim);
        reply = {{"ok", true}};
        if (fields.is_object())
          for (auto& [k, v] : fields.items()) reply[k] = v;
      } catch (const CommandError& e) {
        reply = ErrorOnly(e);
      } catch (const std::exception& e) {
        reply = ErrorOnly(CommandError(command_code::kFailed, "", e.what()));
      }
      work->done(std::move(reply));
      continue;
    }
    // 3. running: pace to wall-clock time; paused: wait for work
    std::unique_lock<std::mutex> lock(mu_);
    auto woken = [&] { return !queue_.empty() || stop_.load() != 0; };
    if (!paused_.load()) {
      if (at_start) return true;
      const double f = factor_.load();
      if (f <= 0) return true;
      if (!anchored_ || factor_changed_.exchange(false)) Reanchor(sim);
      const auto deadline =
          anchor_wall_ +
          std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(
              static_cast<double>(sim.step_count() - anchor_step_) * sim.timestep() / f));
      const auto now = Clock::now();
      if (now >= deadline) return true;
      cv_.wait_until(lock, std::min(deadline, now + kPollInterval), woken);
      continue;
    }
    anchored_ = false;
    cv_.wait_for(lock, kPollInterval, woken);
  }
}

void RunControl::OnStart(const LoopStart&) {
  initial_ = sim_->GetState();
  boundary_step_.store(sim_->step_count());
  boundary_time_.store(sim_->time());
  // a paused run waits for its first step request before the first snapshot, so that
  // snapshot's outputs belong to that request (and clients can subscribe first)
  if (paused_.load()) Gate(*sim_, true);
}

void RunControl::OnFinish(const LoopFinish&) {
  std::deque<Work> left;
  {
    std::lock_guard<std::mutex> lock(mu_);
    ended_.store(true);
    stop_.store(1);
    left.swap(queue_);
    has_work_.store(false);
  }
  if (active_) CompleteSteps(*sim_, true);
  for (Work& w : left) {
    if (w.steps > 0) {
      nlohmann::json r = {
          {"ok", true}, {"step", sim_->step_count()}, {"time_sec", sim_->time()}, {"ended", true}};
      if (w.with_state) {
        const nlohmann::json state = StateJson(*sim_);
        for (auto& [k, v] : state.items()) r[k] = v;
      }
      w.done(std::move(r));
    } else {
      w.done(ErrorOnly(CommandError(command_code::kStopping, "",
                                    "the run stopped before this command was carried out")));
    }
  }
}

}  // namespace penumbra
