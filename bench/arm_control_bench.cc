// controller cost of the arm controllers: physics steps per second of the bundled table
// scene (worlds/models/table_scene.xml: the Panda-class arm, the table and three free boxes)
// under diff_ik (the pick-and-place script of tests/physics/arm_pick_place_test.cc, first
// 6 s: approach, descent, grasp, lift), joint_pd (two joint-space moves) and
// keyframe_playback (three frames), each at 500 Hz (every 2 ms step), against the same
// 6 s episode replayed from its recorded ctrl with no controller attached. the replay is
// bit-identical (same contacts, same solver work), so the difference is the controller plus
// the simulation's controller scheduling (mj_step1 / mj_step2 split). both sides are timed
// on thread CPU time, in alternating order. counters: steps/s of both sides and
// ratio = controlled / replay (issue 3 asks for >= 0.9).
//
// the models are found through $PENUMBRA_MODELS_DIR, else in worlds/models above the
// executable's folder (e.g. build/../worlds/models).

#include <benchmark/benchmark.h>
#include <time.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "penumbra/control/controller_factory.h"
#include "penumbra/physics/simulation.h"

namespace penumbra {
namespace {

std::string ModelsDir() {
  if (const char* env = std::getenv("PENUMBRA_MODELS_DIR")) return env;
  std::filesystem::path p = std::filesystem::canonical("/proc/self/exe").parent_path();
  for (; !p.empty() && p != p.parent_path(); p = p.parent_path())
    if (std::filesystem::exists(p / "worlds/models/table_scene.xml"))
      return (p / "worlds/models").string();
  throw std::runtime_error("worlds/models not found; set PENUMBRA_MODELS_DIR");
}

double ThreadCpuSec() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// the Panda-class arm's servo block (as in worlds/arm.yaml)
const char* kServo =
    "joints: [joint1, joint2, joint3, joint4, joint5, joint6, joint7]\n"
    "actuators: [actuator1, actuator2, actuator3, actuator4, actuator5, actuator6, actuator7]\n"
    "kp: [600, 600, 600, 600, 250, 150, 50]\n"
    "kd: [50, 50, 50, 50, 30, 25, 15]\n"
    "max_velocity: [2.175, 2.175, 2.175, 2.175, 2.61, 2.61, 2.61]\n";

const char* kDiffIk =
    "site: ee\nbase_body: link0\ngripper_actuator: gripper\nspeed_m_s: 0.3\n"
    "commands:\n"
    "  - {t: 0.0, move_to: {xyz: [0.5, -0.15, 0.15], rpy_deg: [180, 0, 0]}}\n"
    "  - {t: 2.8, move_to: {xyz: [0.5, -0.15, 0.025]}, speed_m_s: 0.15}\n"
    "  - {t: 4.6, gripper: close}\n"
    "  - {t: 5.3, move_by: {xyz: [0, 0, 0.15]}, speed_m_s: 0.15}\n";

const char* kJointPd =
    "commands:\n"
    "  - {t: 0.0, q: [0.5, -0.3, 0.2, -2.0, 0.3, 1.8, 0.5]}\n"
    "  - {t: 3.0, q: [-0.4, -0.9, -0.2, -2.5, -0.3, 1.6, 1.0]}\n";

const char* kKeyframes =
    "frames:\n"
    "  - {t: 1.5, q: [0.5, -0.3, 0.2, -2.0, 0.3, 1.8, 0.5]}\n"
    "  - {t: 3.5, q: [-0.4, -0.9, -0.2, -2.5, -0.3, 1.6, 1.0]}\n"
    "  - {t: 5.5, q: [0, -0.785398163, 0, -2.35619449, 0, 1.57079633, 0.785398163]}\n";

void BM_ArmControllerCost(benchmark::State& state, const std::string& type,
                          const std::string& block) {
  constexpr int kSteps = 3000;
  const std::string xml = ModelsDir() + "/table_scene.xml";
  const ControllerConfig cfg{type, std::string(kServo) + block, 0};
  auto controlled = [&]() {
    Simulation sim = Simulation::LoadFromFile(xml);
    sim.AddController(MakeController(cfg, "", "bench"));
    return sim;
  };
  // the episode's ctrl, recorded once (the runs are deterministic)
  std::vector<double> log;
  {
    Simulation sim = controlled();
    for (int i = 0; i < kSteps; ++i) {
      sim.Step();
      log.insert(log.end(), sim.ctrl().begin(), sim.ctrl().end());
    }
  }
  double t_ctrl = 0, t_replay = 0;
  int64_t episodes = 0;
  for (auto _ : state) {
    state.PauseTiming();
    Simulation a = controlled();
    Simulation b = Simulation::LoadFromFile(xml);
    const size_t nu = b.ctrl().size();
    state.ResumeTiming();
    auto run_a = [&] {
      const double t0 = ThreadCpuSec();
      for (int i = 0; i < kSteps; ++i) a.Step();
      t_ctrl += ThreadCpuSec() - t0;
    };
    auto run_b = [&] {
      const double t0 = ThreadCpuSec();
      for (int i = 0; i < kSteps; ++i) {
        std::copy(log.begin() + i * nu, log.begin() + (i + 1) * nu, b.ctrl().begin());
        b.Step();
      }
      t_replay += ThreadCpuSec() - t0;
    };
    if (episodes % 2 == 0) {
      run_a();
      run_b();
    } else {
      run_b();
      run_a();
    }
    if (std::memcmp(a.qpos().data(), b.qpos().data(), a.qpos().size() * sizeof(double)) != 0)
      state.SkipWithError("replay diverged from the controlled run");
    ++episodes;
  }
  state.counters["controlled_steps_per_s"] = static_cast<double>(episodes * kSteps) / t_ctrl;
  state.counters["replay_steps_per_s"] = static_cast<double>(episodes * kSteps) / t_replay;
  state.counters["ratio"] = t_replay / t_ctrl;
}

BENCHMARK_CAPTURE(BM_ArmControllerCost, diff_ik, std::string("diff_ik"), std::string(kDiffIk))
    ->Unit(benchmark::kMillisecond)
    ->MinTime(3.0);
BENCHMARK_CAPTURE(BM_ArmControllerCost, joint_pd, std::string("joint_pd"), std::string(kJointPd))
    ->Unit(benchmark::kMillisecond)
    ->MinTime(3.0);
BENCHMARK_CAPTURE(BM_ArmControllerCost, keyframe_playback, std::string("keyframe_playback"),
                  std::string(kKeyframes))
    ->Unit(benchmark::kMillisecond)
    ->MinTime(3.0);

}  // namespace
}  // namespace penumbra
