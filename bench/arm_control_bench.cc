// controller cost of the arm controllers: physics steps per second of the bundled table
// scene (worlds/models/table_scene.xml: the Panda-class arm, the table and three free boxes)
// under diff_ik (the pick-and-place script of tests/physics/arm_pick_place_test.cc, first
// 6 s: approach, descent, grasp, lift), joint_pd (two joint-space moves) and
// keyframe_playback (three frames), each at 500 Hz (every 2 ms step), against the same
// 6 s episode replayed from its recorded ctrl with no controller attached. the replay is
// bit-identical (same contacts, same solver work), so the difference is the controller plus
// the simulation's controller scheduling (mj_step1 / mj_step2 split). both sides are timed
// on thread CPU time, in alternating order. counters: steps/s of both sides and
// ratio = controlled / replay (the target: >= 0.9).
//
// the models are found through $PENUMBRA_MODELS_DIR, else in worlds/models above the
// executable's folder (e.g. build/../worlds/models).

#include <benchmark/benchmark.h>

#include <string>

#include "controller_cost_harness.h"
#include "penumbra/config/yaml_document.h"

namespace penumbra {
namespace {

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
  const std::string xml = bench::ModelsDir("table_scene.xml") + "/table_scene.xml";
  bench::MeasureControllerCost(state,
                               {.steps = 3000,
                                .load = [&] { return Simulation::LoadFromFile(xml); },
                                .controller = {type, ParseYaml(std::string(kServo) + block), 0}});
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
