// controller cost of trot_gait: physics steps per second of the bundled quadruped and
// quadruped_arm trotting at 0.5 / 0.4 m/s on a flat floor under trot_gait (at its default
// 250 Hz, every 2nd 2 ms step, and at 500 Hz, every step), against the same 4 s episode
// replayed from its recorded ctrl with no controller attached. the replay is bit-identical (same
// contacts, same solver work), so the difference is the controller plus the simulation's controller
// scheduling (mj_step1 / mj_step2 split). both sides are timed on thread CPU time (less disturbed
// by other processes than wall time), in alternating order. counters: steps/s of both sides and
// ratio = controlled / replay (the target: >= 0.9). a third side replays the log through
// a controller that only copies it into ctrl at every step: scheduling_ratio = that / replay
// is the part of the cost that any controller running at every step pays.
//
// the models are found through $PENUMBRA_MODELS_DIR, else in worlds/models above the
// executable's folder (e.g. build/../worlds/models).

#include <benchmark/benchmark.h>

#include <optional>
#include <string>

#include "controller_cost_harness.h"
#include "penumbra/config/yaml_document.h"

namespace penumbra {
namespace {

std::string SceneXml(const std::string& robot) {
  return "<mujoco><worldbody><geom name=\"floor\" type=\"plane\" size=\"0 0 0.05\"/></worldbody>"
         "<include file=\"" +
         robot + ".xml\"/></mujoco>";
}

std::string GaitYaml(double speed, const std::string& extra) {
  std::string s = "base_body: trunk\nlegs:\n";
  for (const std::string l : {"FR", "FL", "RR", "RL"})
    s += "  " + l + ": {hip: " + l + "_hip, thigh: " + l + "_thigh, calf: " + l +
         "_calf, foot: " + l + "_foot}\n";
  return s + "commands: [{t: 0, vx: " + std::to_string(speed) + "}]\n" + extra;
}

void BM_TrotGaitCost(benchmark::State& state, const std::string& robot, double speed,
                     const std::string& extra) {
  constexpr int kSteps = 2000;
  const std::string dir = bench::ModelsDir("quadruped.xml");
  const std::string xml = SceneXml(robot);
  const ControllerConfig cfg{"trot_gait", ParseYaml(GaitYaml(speed, extra)), 0};
  bench::MeasureControllerCost(
      state, {.steps = kSteps,
              .load = [&] { return Simulation::LoadFromString(xml, std::nullopt, dir); },
              .controller = cfg,
              .scheduling_side = true});
}

const std::string kArmGains = "swing_kp: 200\nswing_kd: 4\nswing_height_m: 0.1\n";
BENCHMARK_CAPTURE(BM_TrotGaitCost, quadruped, std::string("quadruped"), 0.5, std::string())
    ->Unit(benchmark::kMillisecond)
    ->MinTime(3.0);
BENCHMARK_CAPTURE(BM_TrotGaitCost, quadruped_arm, std::string("quadruped_arm"), 0.4, kArmGains)
    ->Unit(benchmark::kMillisecond)
    ->MinTime(3.0);
BENCHMARK_CAPTURE(BM_TrotGaitCost, quadruped_500hz, std::string("quadruped"), 0.5,
                  std::string("rate_hz: 500\n"))
    ->Unit(benchmark::kMillisecond)
    ->MinTime(3.0);
BENCHMARK_CAPTURE(BM_TrotGaitCost, quadruped_arm_500hz, std::string("quadruped_arm"), 0.4,
                  kArmGains + "rate_hz: 500\n")
    ->Unit(benchmark::kMillisecond)
    ->MinTime(3.0);

}  // namespace
}  // namespace penumbra
