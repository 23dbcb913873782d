#include "penumbra/physics/physics_benchmark.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <mutex>
#include <sstream>

#include "penumbra/core/error.h"
#include "penumbra/physics/mujoco_runtime.h"
#include "penumbra/physics/simulation.h"

namespace penumbra {

PhysicsBenchResult BenchmarkPhysics(const std::string& mjcf_path, double sim_seconds) {
  if (!(std::isfinite(sim_seconds) && sim_seconds > 0))
    throw ConfigError("", 0, "--seconds",
                      "got " + std::to_string(sim_seconds) + "; expected a number > 0 (s)");
  Simulation sim = Simulation::LoadFromFile(mjcf_path);
  Simulation plain = Simulation::LoadFromFile(mjcf_path);
  mjModel* m = nullptr;
  {
    std::lock_guard<std::mutex> lock(MujocoLoaderMutex());
    m = LoadMujocoXmlLocked(mjcf_path, nullptr, mjcf_path, nullptr);
  }
  mjData* d = mj_makeData(m);
  struct Cleanup {
    mjModel* m;
    mjData* d;
    ~Cleanup() {
      mj_deleteData(d);
      mj_deleteModel(m);
    }
  } cleanup{m, d};

  const double dt = sim.timestep();
  const int64_t total = std::max<int64_t>(1, static_cast<int64_t>(std::llround(sim_seconds / dt)));
  // short alternating blocks: frequency scaling and other load hit both sides alike
  constexpr int64_t kBlockSteps = 250;
  const int64_t blocks = (total + kBlockSteps - 1) / kBlockSteps;
  constexpr double kSnapshotHz = 30.0;
  WorldSnapshot snapshot;
  int64_t next_frame = 0;
  double sim_wall = 0, plain_wall = 0, bare_wall = 0;
  int64_t done = 0;
  using Clock = std::chrono::steady_clock;

  auto run_sim = [&](int64_t n) {
    const auto t0 = Clock::now();
    for (int64_t i = 0; i < n; ++i) {
      sim.Step();
      // a camera frame at the first step whose time is at least k / 30 s, as the runner takes
      // it: poses only (sensors, where a world has them, add full snapshots at their rates)
      if (sim.time() + 1e-6 * dt >= next_frame / kSnapshotHz) {
        sim.Snapshot(&snapshot, Simulation::SnapshotContent::kPoses);
        next_frame = static_cast<int64_t>(std::floor((sim.time() + 1e-6 * dt) * kSnapshotHz)) + 1;
      }
    }
    sim_wall += std::chrono::duration<double>(Clock::now() - t0).count();
  };
  auto run_plain = [&](int64_t n) {
    const auto t0 = Clock::now();
    for (int64_t i = 0; i < n; ++i) plain.Step();
    plain_wall += std::chrono::duration<double>(Clock::now() - t0).count();
  };
  auto run_bare = [&](int64_t n) {
    const auto t0 = Clock::now();
    for (int64_t i = 0; i < n; ++i) mj_step(m, d);
    bare_wall += std::chrono::duration<double>(Clock::now() - t0).count();
  };

  // untimed warm-up of all three (same number of steps, so all keep the same state)
  const int64_t warmup = std::min<int64_t>(total, kBlockSteps);
  run_sim(warmup);
  run_plain(warmup);
  run_bare(warmup);
  sim_wall = plain_wall = bare_wall = 0;
  for (int64_t b = 0; b < blocks; ++b) {
    const int64_t n = std::min(kBlockSteps, total - done);
    done += n;
    switch (b % 3) {
      case 0:
        run_sim(n);
        run_plain(n);
        run_bare(n);
        break;
      case 1:
        run_bare(n);
        run_sim(n);
        run_plain(n);
        break;
      default:
        run_plain(n);
        run_bare(n);
        run_sim(n);
        break;
    }
  }
  PhysicsBenchResult r;
  r.steps = total;
  r.penumbra_steps_per_sec = sim_wall > 0 ? total / sim_wall : 0;
  r.step_only_steps_per_sec = plain_wall > 0 ? total / plain_wall : 0;
  r.bare_steps_per_sec = bare_wall > 0 ? total / bare_wall : 0;
  r.ratio = r.bare_steps_per_sec > 0 ? r.penumbra_steps_per_sec / r.bare_steps_per_sec : 0;
  r.step_only_ratio =
      r.bare_steps_per_sec > 0 ? r.step_only_steps_per_sec / r.bare_steps_per_sec : 0;
  return r;
}

int64_t RunBareMujocoLoop(const std::string& mjcf_path, double sim_seconds) {
  if (!(std::isfinite(sim_seconds) && sim_seconds > 0))
    throw ConfigError("", 0, "--seconds",
                      "got " + std::to_string(sim_seconds) + "; expected a number > 0 (s)");
  // as a program with MuJoCo alone loads it (mj_loadXML keeps its compiler model)
  char error[1000] = "";
  mjModel* m = nullptr;
  {
    std::lock_guard<std::mutex> lock(MujocoLoaderMutex());
    m = mj_loadXML(mjcf_path.c_str(), nullptr, error, sizeof(error));
  }
  if (m == nullptr) throw ConfigError(mjcf_path, 0, "", std::string("MuJoCo: ") + error);
  mjData* d = mj_makeData(m);
  const int64_t total =
      std::max<int64_t>(1, static_cast<int64_t>(std::llround(sim_seconds / m->opt.timestep)));
  for (int64_t i = 0; i < total; ++i) mj_step(m, d);
  mj_deleteData(d);
  mj_deleteModel(m);
  return total;
}

int64_t PeakResidentKiB() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line)) {
    // "VmHWM:     12345 kB"
    if (line.rfind("VmHWM:", 0) != 0) continue;
    std::istringstream fields(line.substr(6));
    int64_t kib = 0;
    fields >> kib;
    return kib;
  }
  return 0;
}

}  // namespace penumbra
