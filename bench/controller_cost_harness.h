#pragma once
// the harness of the controller cost benchmarks (arm_control_bench.cc,
// multirotor_pid_bench.cc, trot_gait_bench.cc): one episode of a model under a controller
// against the same episode replayed from its recorded ctrl with no controller attached. the
// replay is bit-identical (same contacts, same solver work), so the difference is the
// controller plus the simulation's controller scheduling (mj_step1 / mj_step2 split). both
// sides are timed on thread CPU time (less disturbed by other processes than wall time), in
// alternating order. counters: steps/s of both sides and ratio = controlled / replay (the
// target: >= 0.9). optionally a third side replays the log through a controller that only
// copies it into ctrl at every step: scheduling_ratio = that / replay is the part of the cost
// that any controller running at every step pays.

#include <benchmark/benchmark.h>
#include <time.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "penumbra/control/controller.h"
#include "penumbra/control/controller_factory.h"
#include "penumbra/physics/simulation.h"

namespace penumbra::bench {

/// the bundled models' folder: $PENUMBRA_MODELS_DIR, else the first worlds/models above the
/// executable's folder (e.g. build/../worlds/models) that holds `probe_file` (e.g.
/// "quadrotor.xml"). @throws std::runtime_error when neither is found.
inline std::string ModelsDir(const std::string& probe_file) {
  if (const char* env = std::getenv("PENUMBRA_MODELS_DIR")) return env;
  std::filesystem::path p = std::filesystem::canonical("/proc/self/exe").parent_path();
  for (; !p.empty() && p != p.parent_path(); p = p.parent_path())
    if (std::filesystem::exists(p / "worlds/models" / probe_file))
      return (p / "worlds/models").string();
  throw std::runtime_error("worlds/models not found; set PENUMBRA_MODELS_DIR");
}

/// CPU time of the calling thread (s), CLOCK_THREAD_CPUTIME_ID.
inline double ThreadCpuSec() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

/// writes the recorded ctrl of step k (`nu` values from `log`) at its k-th update; runs at
/// every step (rate_hz 0). `log` must outlive it.
class ReplayController final : public Controller {
 public:
  ReplayController(const std::vector<double>* log, size_t nu)
      : Controller(ControllerContext{}), log_(log), nu_(nu) {}
  std::string type() const override { return "replay"; }
  double rate_hz() const override { return 0; }
  std::vector<NameRequirement> RequiredNames() const override { return {}; }
  void Reset() override { k_ = 0; }
  void Compute(const ControlInput&, std::span<double> ctrl) override {
    std::copy(log_->begin() + k_ * nu_, log_->begin() + (k_ + 1) * nu_, ctrl.begin());
    ++k_;
  }

 protected:
  void OnInitialize(const ModelInfo&, const std::vector<int>&) override {}

 private:
  const std::vector<double>* log_;
  size_t nu_;
  size_t k_ = 0;
};

/// one controller cost benchmark.
struct ControllerCostCase {
  int steps = 0;                     ///< physics steps per episode
  std::function<Simulation()> load;  ///< a fresh simulation of the model, no controller
  ControllerConfig controller;       ///< attached through MakeController(controller, "", "bench")
  bool scheduling_side = false;      ///< also time the ReplayController side
};

/// runs the benchmark loop of `c` on `state`: records the controlled episode's ctrl once, then
/// per iteration times the controlled run, the replay (and the ReplayController side), in
/// alternating order, and fails the benchmark when a replay's final qpos is not bit-identical
/// to the controlled run's. sets the counters controlled_steps_per_s, replay_steps_per_s,
/// ratio (= replay time / controlled time) and, with the third side, scheduling_ratio.
inline void MeasureControllerCost(benchmark::State& state, const ControllerCostCase& c) {
  const int steps = c.steps;
  auto controlled = [&]() {
    Simulation sim = c.load();
    sim.AddController(MakeController(c.controller, "", "bench"));
    return sim;
  };
  // the episode's ctrl, recorded once (the runs are deterministic)
  std::vector<double> log;
  {
    Simulation sim = controlled();
    for (int i = 0; i < steps; ++i) {
      sim.Step();
      log.insert(log.end(), sim.ctrl().begin(), sim.ctrl().end());
    }
  }
  auto same_qpos = [](const Simulation& x, const Simulation& y) {
    return std::memcmp(x.qpos().data(), y.qpos().data(), x.qpos().size() * sizeof(double)) == 0;
  };
  double t_ctrl = 0, t_replay = 0, t_sched = 0;
  int64_t episodes = 0;
  for (auto _ : state) {
    state.PauseTiming();
    Simulation a = controlled();
    Simulation b = c.load();
    const size_t nu = b.ctrl().size();
    std::unique_ptr<Simulation> s;
    if (c.scheduling_side) {
      s = std::make_unique<Simulation>(c.load());
      s->AddController(std::make_unique<ReplayController>(&log, nu));
    }
    state.ResumeTiming();
    auto run_a = [&] {
      const double t0 = ThreadCpuSec();
      for (int i = 0; i < steps; ++i) a.Step();
      t_ctrl += ThreadCpuSec() - t0;
    };
    auto run_b = [&] {
      const double t0 = ThreadCpuSec();
      for (int i = 0; i < steps; ++i) {
        std::copy(log.begin() + i * nu, log.begin() + (i + 1) * nu, b.ctrl().begin());
        b.Step();
      }
      t_replay += ThreadCpuSec() - t0;
    };
    auto run_s = [&] {
      if (!s) return;
      const double t0 = ThreadCpuSec();
      for (int i = 0; i < steps; ++i) s->Step();
      t_sched += ThreadCpuSec() - t0;
    };
    if (episodes % 2 == 0) {
      run_a();
      run_b();
      run_s();
    } else {
      run_s();
      run_b();
      run_a();
    }
    if (!same_qpos(a, b) || (s && !same_qpos(a, *s)))
      state.SkipWithError("replay diverged from the controlled run");
    ++episodes;
  }
  state.counters["controlled_steps_per_s"] = static_cast<double>(episodes * steps) / t_ctrl;
  state.counters["replay_steps_per_s"] = static_cast<double>(episodes * steps) / t_replay;
  state.counters["ratio"] = t_replay / t_ctrl;
  if (c.scheduling_side) state.counters["scheduling_ratio"] = t_replay / t_sched;
}

}  // namespace penumbra::bench
