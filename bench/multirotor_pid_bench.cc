// controller cost of multirotor_pid: physics steps per second of the bundled quadrotor
// taking off and flying the 4 m waypoint square at 1 m/s over a floor under multirotor_pid
// (500 Hz, every 2 ms step), against the same 10 s episode replayed from its recorded ctrl
// with no controller attached. the replay is bit-identical (same rotor activations, same
// contacts at takeoff), so the difference is the controller plus the simulation's controller
// scheduling. both sides are timed on thread CPU time (less disturbed by other processes
// than wall time), in alternating order. counters: steps/s of both sides and
// ratio = controlled / replay (the target: >= 0.9).
//
// the model is found through $PENUMBRA_MODELS_DIR, else in worlds/models above the
// executable's folder (e.g. build/../worlds/models).

#include <benchmark/benchmark.h>

#include <optional>
#include <string>

#include "controller_cost_harness.h"
#include "penumbra/config/yaml_document.h"

namespace penumbra {
namespace {

void BM_MultirotorPidCost(benchmark::State& state) {
  constexpr int kSteps = 5000;  // 10 s: takeoff, then the first two and a half sides
  const std::string dir = bench::ModelsDir("quadrotor.xml");
  const std::string xml =
      "<mujoco><worldbody><geom name=\"floor\" type=\"plane\" size=\"0 0 0.05\"/></worldbody>"
      "<include file=\"quadrotor.xml\"/></mujoco>";
  const ControllerConfig cfg{
      "multirotor_pid",
      ParseYaml("base_body: base\n"
                "rotor_actuators: [thrust_fr, thrust_rl, thrust_fl, thrust_rr]\n"
                "commands:\n"
                "  - {t: 0, mode: takeoff, altitude_m: 1.5}\n"
                "  - {t: 3, mode: waypoints, speed_m_s: 1.0,\n"
                "     waypoints: [[4, 0, 1.5], [4, 4, 1.5], [0, 4, 1.5], [0, 0, 1.5]]}\n"),
      0};
  bench::MeasureControllerCost(
      state, {.steps = kSteps,
              .load = [&] { return Simulation::LoadFromString(xml, std::nullopt, dir); },
              .controller = cfg});
}

BENCHMARK(BM_MultirotorPidCost)->Unit(benchmark::kMillisecond)->MinTime(3.0);

}  // namespace
}  // namespace penumbra
