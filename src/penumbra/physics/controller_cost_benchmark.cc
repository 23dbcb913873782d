#include "penumbra/physics/controller_cost_benchmark.h"

#include <time.h>

#include <algorithm>
#include <cstring>
#include <vector>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

double ThreadCpuSec() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

}  // namespace

ControllerCostResult BenchmarkControllerCost(const std::string& mjcf_path,
                                             const std::function<void(Simulation&)>& add_controllers,
                                             int64_t steps, int episodes) {
  if (steps <= 0 || episodes <= 0)
    throw ConfigError("", 0, "bench physics", "steps and episodes must be > 0");
  auto controlled = [&] {
    Simulation sim = Simulation::LoadFromFile(mjcf_path);
    add_controllers(sim);
    return sim;
  };

  // the episode's ctrl and final qpos, recorded once (runs are deterministic)
  std::vector<double> log, final_qpos;
  {
    Simulation sim = controlled();
    for (int64_t i = 0; i < steps; ++i) {
      sim.Step();
      log.insert(log.end(), sim.ctrl().begin(), sim.ctrl().end());
    }
    final_qpos.assign(sim.qpos().begin(), sim.qpos().end());
  }

  ControllerCostResult r;
  r.steps = steps;
  double t_controlled = 0, t_replay = 0;
  for (int e = 0; e < episodes; ++e) {
    Simulation a = controlled();
    Simulation b = Simulation::LoadFromFile(mjcf_path);
    const size_t nu = b.ctrl().size();
    auto run_controlled = [&] {
      const double t0 = ThreadCpuSec();
      for (int64_t i = 0; i < steps; ++i) a.Step();
      t_controlled += ThreadCpuSec() - t0;
    };
    auto run_replay = [&] {
      const double t0 = ThreadCpuSec();
      for (int64_t i = 0; i < steps; ++i) {
        std::copy_n(log.begin() + i * nu, nu, b.ctrl().begin());
        b.Step();
      }
      t_replay += ThreadCpuSec() - t0;
    };
    if (e % 2 == 0) {
      run_controlled();
      run_replay();
    } else {
      run_replay();
      run_controlled();
    }
    if (e == 0)
      r.replay_identical = std::memcmp(b.qpos().data(), final_qpos.data(),
                                       final_qpos.size() * sizeof(double)) == 0;
  }
  r.controlled_steps_per_sec = static_cast<double>(steps) * episodes / t_controlled;
  r.replay_steps_per_sec = static_cast<double>(steps) * episodes / t_replay;
  r.ratio = r.controlled_steps_per_sec / r.replay_steps_per_sec;
  return r;
}

}  // namespace penumbra
