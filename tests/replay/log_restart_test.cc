// a run restarted from its run log: a fresh simulation set to a logged mid-run state (through
// the replay's StateMap) continues as the logged run did, bit for bit in every field of the
// state, for a model whose next step depends on more than qpos and qvel: a delayed motor
// (history buffer), a yielding spring (plastic state) and an equality switched off mid-run
// (eq_active).
#include <gtest/gtest.h>

#include <bit>
#include <cmath>

#include "common/temp_dir.h"
#include "penumbra/live/run_log_header.h"
#include "penumbra/physics/simulation.h"
#include "penumbra/replay/state_map.h"
#include "penumbra/runlog/run_log_reader.h"
#include "penumbra/runlog/run_log_writer.h"

namespace penumbra {
namespace {

constexpr char kRestartModel[] = R"(<mujoco><option timestep="0.002"/><worldbody>
  <geom name="floor" type="plane" size="3 3 0.1"/>
  <body name="arm" pos="0 0 1"><joint name="hinge" axis="0 1 0" stiffness="5" springyield="5"/>
    <geom type="capsule" fromto="0 0 0 0.4 0 0" size="0.03" mass="0.5"/></body>
  <body name="ball" pos="1 0 0.5"><freejoint name="free"/><geom type="sphere" size="0.1"/></body>
  </worldbody>
  <equality><weld name="hold" body1="ball"/></equality>
  <actuator><motor name="m" joint="hinge" nsample="10" delay="0.02"/></actuator></mujoco>)";

constexpr int64_t kRestartLastStep = 400;
constexpr int64_t kRestartWeldOffStep = 120;
constexpr int64_t kRestartStep = 250;

double RestartCommandAt(int64_t k) { return 4.0 * std::sin(0.05 * static_cast<double>(k)); }

// the first field and entry where `a` and `b` differ bit for bit, or ""
std::string FirstStateDifference(const SimState& a, const SimState& b) {
  std::string diff;
  if (a.step != b.step) return "step";
  ForEachStateField(
      [&](const StateFieldInfo& f, const auto& x, const auto& y) {
        if (!diff.empty()) return;
        if (x.size() != y.size()) diff = "size of " + std::string(f.name);
        for (size_t i = 0; i < x.size() && diff.empty(); ++i)
          if (std::bit_cast<uint64_t>(x[i]) != std::bit_cast<uint64_t>(y[i]))
            diff = std::string(f.name) + "[" + std::to_string(i) + "]";
      },
      a, b);
  return diff;
}

// steps 0..kRestartLastStep recorded; before step k the motor gets RestartCommandAt(k); the weld is
// switched off at kRestartWeldOffStep (SetState, as a restored state or a reset would)
std::string RecordRestartRun(const testing::TempDir& tmp) {
  const std::string path = (tmp.path() / "run.plog").string();
  Simulation sim = Simulation::LoadFromString(kRestartModel);
  RunLogHeader h;
  h.penumbra_version = "test";
  h.mujoco_version = "4.0.0";
  h.composed_mjcf = kRestartModel;
  h.timestep_sec = sim.timestep();
  h.layout = RunLogLayoutOf(sim);
  RunLogWriterOptions o;
  o.chunk_steps = 64;
  RunLogWriter w(path, h, o);
  for (int64_t k = 0; k <= kRestartLastStep; ++k) {
    sim.ctrl()[0] = RestartCommandAt(k);
    if (k == kRestartWeldOffStep) {
      SimState s = sim.GetState();
      s.eq_active = {0};
      sim.SetState(s);
    }
    w.Append(sim.GetState());
    if (k < kRestartLastStep) sim.Step();
  }
  w.Close();
  return path;
}

TEST(LogRestart, AFreshSimulationSetToALoggedStateContinuesAsTheLogBitForBit) {
  testing::TempDir tmp;
  const std::string path = RecordRestartRun(tmp);
  RunLogReader log = RunLogReader::Open(path);
  EXPECT_EQ(log.header().format_version, kRunLogFormatVersion);
  const RunLogLayout& layout = log.header().layout;
  EXPECT_EQ(layout.nhistory,
            static_cast<int>(Simulation::LoadFromString(kRestartModel).GetState().history.size()));
  EXPECT_GE(layout.nhistory, 10);
  EXPECT_EQ(layout.neq, 1);
  EXPECT_EQ(layout.nplastic, 1);

  Simulation fresh = Simulation::LoadFromString(kRestartModel);
  const StateMap map(layout, RunLogLayoutOf(fresh), path);
  EXPECT_TRUE(map.identity());
  ASSERT_TRUE(log.SeekStep(kRestartStep));
  StepRecord r;
  ASSERT_TRUE(log.NextStep(&r));
  ASSERT_EQ(r.step, kRestartStep);
  EXPECT_EQ(r.eq_active, std::vector<double>{0});
  SimState s = fresh.GetState();
  map.Apply(r, &s);
  fresh.SetState(s);
  EXPECT_EQ(FirstStateDifference(fresh.GetState(), r), "");

  // every later step, every field, as logged
  int64_t compared = 0;
  while (log.NextStep(&r)) {
    fresh.Step();
    fresh.ctrl()[0] = r.ctrl[0];  // the command the run gave before logging this step
    ASSERT_EQ(FirstStateDifference(fresh.GetState(), r), "") << "step " << r.step;
    ++compared;
  }
  EXPECT_EQ(compared, kRestartLastStep - kRestartStep);
}

}  // namespace
}  // namespace penumbra
