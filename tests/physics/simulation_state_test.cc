// Simulation::GetState / SetState: a restart from a saved state is bit-exact (SimState).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "penumbra/core/error.h"
#include "penumbra/physics/simulation.h"

namespace penumbra {
namespace {

// the bundled Go1 quadruped (12 torque motors, a free trunk) on a floor plane: it walks its
// joints through a PD controller and its feet keep touching the floor (contacts)
std::string QuadrupedOnFloorXml() {
  const std::filesystem::path file =
      std::filesystem::path(PENUMBRA_SOURCE_DIR) / "worlds" / "models" / "quadruped.xml";
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  std::string xml = text.str();
  const size_t at = xml.find("<worldbody>");
  EXPECT_NE(at, std::string::npos);
  xml.insert(at + std::string("<worldbody>").size(),
             R"(<geom name="floor" type="plane" size="5 5 0.1"/>)");
  return xml;
}

// a controller that keeps no memory: torques from the current state and sim time only
class StatelessPd final : public Controller {
 public:
  StatelessPd() : Controller({"", 0, "test"}) {}
  std::string type() const override { return "stateless_pd"; }
  double rate_hz() const override { return 100; }  // every 5th step at 2 ms
  std::vector<NameRequirement> RequiredNames() const override { return {}; }
  void Reset() override {}  // no memory
  void Compute(const ControlInput& in, std::span<double> ctrl) override {
    const ModelInfo& info = in.model();
    for (size_t a = 0; a < info.actuators.size(); ++a) {
      const JointInfo& j = info.joints.at(info.actuators[a].joint);
      const double target = info.keys.at(0).qpos[j.qpos_adr] +
                            0.3 * std::sin(2 * M_PI * 1.5 * in.time_sec() + static_cast<double>(a));
      ctrl[a] = 20.0 * (target - in.qpos()[j.qpos_adr]) - 0.5 * in.qvel()[j.dof_adr];
    }
  }

 protected:
  void OnInitialize(const ModelInfo&, const std::vector<int>&) override {}
};

Simulation LoadQuadruped() {
  Simulation sim = Simulation::LoadFromString(QuadrupedOnFloorXml(), 0.002);
  sim.AddController(std::make_unique<StatelessPd>());
  return sim;
}

struct Trace {
  std::vector<std::vector<double>> qpos, qvel;
  size_t max_contacts = 0;
};

Trace StepAndRecord(Simulation* sim, int steps) {
  Trace t;
  for (int i = 0; i < steps; ++i) {
    sim->Step();
    t.qpos.emplace_back(sim->qpos().begin(), sim->qpos().end());
    t.qvel.emplace_back(sim->qvel().begin(), sim->qvel().end());
    if (i % 50 == 0) t.max_contacts = std::max(t.max_contacts, sim->Snapshot().contacts.size());
  }
  return t;
}

// EXPECT_EQ on every double: bit-identical, not close
void ExpectIdentical(const Trace& a, const Trace& b) {
  ASSERT_EQ(a.qpos.size(), b.qpos.size());
  for (size_t i = 0; i < a.qpos.size(); ++i) {
    for (size_t k = 0; k < a.qpos[i].size(); ++k)
      ASSERT_EQ(a.qpos[i][k], b.qpos[i][k]) << "step " << i << " qpos[" << k << "]";
    for (size_t k = 0; k < a.qvel[i].size(); ++k)
      ASSERT_EQ(a.qvel[i][k], b.qvel[i][k]) << "step " << i << " qvel[" << k << "]";
  }
}

TEST(SimulationState, RestoringMidRunRepeatsTheFollowingStepsBitForBit) {
  Simulation sim = LoadQuadruped();
  StepAndRecord(&sim, 301);  // lands, mid-way between two controller updates
  const SimState saved = sim.GetState();
  EXPECT_EQ(saved.step, 301);
  EXPECT_EQ(saved.time_sec, sim.time());
  const Trace first = StepAndRecord(&sim, 400);
  ASSERT_GT(first.max_contacts, 0u);  // the feet touch the floor
  // the run moved on: restoring has something to undo
  ASSERT_NE(first.qpos.back(), std::vector<double>(saved.qpos));

  sim.SetState(saved);
  EXPECT_EQ(sim.step_count(), 301);
  EXPECT_EQ(sim.time(), saved.time_sec);
  ExpectIdentical(first, StepAndRecord(&sim, 400));
}

TEST(SimulationState, AFreshSimulationOfTheSameModelContinuesIdentically) {
  Simulation a = LoadQuadruped();
  StepAndRecord(&a, 257);
  const SimState saved = a.GetState();
  const Trace rest = StepAndRecord(&a, 300);

  Simulation b = LoadQuadruped();
  b.SetState(saved);
  ExpectIdentical(rest, StepAndRecord(&b, 300));
}

TEST(SimulationState, AStateOfAnotherModelIsRefusedNamingTheField) {
  Simulation sim = LoadQuadruped();
  SimState s = sim.GetState();
  s.qvel.pop_back();
  try {
    sim.SetState(s);
    FAIL() << "expected an Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("qvel has 17 entries; expected 18"), std::string::npos)
        << e.what();
  }
  s = sim.GetState();
  s.step = 10;  // time_sec is that of step 0
  EXPECT_THROW(sim.SetState(s), Error);
  s.controller_next_update.clear();
  EXPECT_THROW(sim.SetState(s), Error);
}

}  // namespace
}  // namespace penumbra

namespace penumbra {
namespace {

// two mocap bodies, one of them driven: the kinematic replay's tools (SetState of a recorded
// state, then ApplyMocapDrivers for the driven bodies the recording lacks)
TEST(SimulationState, ApplyMocapDriversPosesOnlyTheListedDrivenBodies) {
  Simulation sim = Simulation::LoadFromString(R"(
    <mujoco><worldbody>
      <body name="a" mocap="true" pos="1 0 0"><geom size="0.1"/></body>
      <body name="b" mocap="true" pos="2 0 0"><geom size="0.1"/></body>
      <body><freejoint/><geom size="0.1"/></body>
    </worldbody></mujoco>)");
  EXPECT_EQ(sim.MocapBodyNames(), (std::vector<std::string>{"a", "b"}));
  sim.AddMocapDriver("b", [](double t) {
    Pose X = Pose::Identity();
    X.translation() = Eigen::Vector3d(5 + t, 0, 0);
    return X;
  });
  SimState s = sim.GetState();
  s.step = 100;
  s.time_sec = SimTimeOfStep(100, sim.timestep());
  s.mocap_pos = {7, 7, 7, 8, 8, 8};
  sim.SetState(s);
  // SetState alone keeps the given poses
  EXPECT_EQ(sim.GetState().mocap_pos, (std::vector<double>{7, 7, 7, 8, 8, 8}));
  // "a" has no driver: listed or not it keeps its pose; "b" is posed for t only when listed
  const std::vector<int> only_a = {0};
  sim.ApplyMocapDrivers(only_a);
  EXPECT_EQ(sim.GetState().mocap_pos, (std::vector<double>{7, 7, 7, 8, 8, 8}));
  const std::vector<int> both = {0, 1};
  sim.ApplyMocapDrivers(both);
  EXPECT_EQ(sim.GetState().mocap_pos, (std::vector<double>{7, 7, 7, 5 + sim.time(), 0, 0}));
  EXPECT_EQ(sim.Snapshot().X_WB[2].translation(), Eigen::Vector3d(5 + sim.time(), 0, 0));
  const std::vector<int> bad = {2};
  EXPECT_THROW(sim.ApplyMocapDrivers(bad), Error);
}

}  // namespace
}  // namespace penumbra

namespace penumbra {
namespace {

// MuJoCo 4's state beyond qpos ... userdata: a motor that acts with a 20 ms delay (a history
// buffer of 10 samples: docs XMLreference actuator nsample / delay), a hinge whose spring
// yields (springyield: its reference moves, mjData.plastic), a ball welded to the world (an
// equality constraint, switched through eq_active)
constexpr char kMujoco4StateXml[] = R"(<mujoco><option timestep="0.002"/><worldbody>
  <geom name="floor" type="plane" size="3 3 0.1"/>
  <body name="arm" pos="0 0 1"><joint name="hinge" axis="0 1 0" stiffness="5" springyield="5"/>
    <geom type="capsule" fromto="0 0 0 0.4 0 0" size="0.03" mass="0.5"/></body>
  <body name="ball" pos="1 0 0.5"><freejoint/><geom type="sphere" size="0.1"/></body>
  </worldbody>
  <equality><weld name="hold" body1="ball"/></equality>
  <actuator><motor name="m" joint="hinge" nsample="10" delay="0.02"/></actuator></mujoco>)";

// the motor's command at step k: a pure function of the step, so a restart can repeat it
double CommandAt(int64_t k) { return 4.0 * std::sin(0.05 * static_cast<double>(k)); }

// `steps` steps, each with the command of the step it starts from
Trace StepWithCommands(Simulation* sim, int steps) {
  Trace t;
  for (int i = 0; i < steps; ++i) {
    sim->ctrl()[0] = CommandAt(sim->step_count());
    sim->Step();
    t.qpos.emplace_back(sim->qpos().begin(), sim->qpos().end());
    t.qvel.emplace_back(sim->qvel().begin(), sim->qvel().end());
  }
  return t;
}

bool SameTrace(const Trace& a, const Trace& b) { return a.qpos == b.qpos && a.qvel == b.qvel; }

// the run every test restarts: 150 steps of commands, the weld switched off at step 100
// (through SetState, as a restored state would), 100 more; the state then and what followed
struct Mujoco4Run {
  SimState saved;
  Trace rest;
};
Mujoco4Run RunMujoco4Model() {
  Simulation sim = Simulation::LoadFromString(kMujoco4StateXml);
  StepWithCommands(&sim, 100);
  SimState off = sim.GetState();
  EXPECT_EQ(off.eq_active, std::vector<double>{1});
  off.eq_active = {0};
  sim.SetState(off);
  EXPECT_EQ(sim.GetState().eq_active, std::vector<double>{0});
  StepWithCommands(&sim, 150);
  Mujoco4Run run;
  run.saved = sim.GetState();
  run.rest = StepWithCommands(&sim, 200);
  return run;
}

TEST(SimulationState, HistoryEqActiveAndPlasticStateRestartBitExactly) {
  const Mujoco4Run run = RunMujoco4Model();
  const SimState& saved = run.saved;
  // the state holds them: 10 samples of the delayed motor (with their times), the weld off, the
  // hinge spring's moved reference
  Simulation fresh = Simulation::LoadFromString(kMujoco4StateXml);
  const SimState initial = fresh.GetState();
  EXPECT_GE(saved.history.size(), 10u);
  EXPECT_NE(saved.history, initial.history);
  EXPECT_EQ(saved.eq_active, std::vector<double>{0});
  EXPECT_EQ(initial.eq_active, std::vector<double>{1});
  ASSERT_EQ(saved.plastic.size(), 1u);
  EXPECT_NE(saved.plastic, initial.plastic);  // the spring yielded
  EXPECT_TRUE(saved.plugin_state.empty());

  // a fresh simulation of the model set to that state continues bit for bit
  fresh.SetState(saved);
  ExpectIdentical(run.rest, StepWithCommands(&fresh, 200));

  // and each of the three is needed: restored without it, the run goes elsewhere
  const auto without = [&](std::vector<double> SimState::*field) {
    Simulation other = Simulation::LoadFromString(kMujoco4StateXml);
    SimState s = saved;
    s.*field = initial.*field;
    other.SetState(s);
    return StepWithCommands(&other, 200);
  };
  EXPECT_FALSE(SameTrace(run.rest, without(&SimState::history))) << "history";
  EXPECT_FALSE(SameTrace(run.rest, without(&SimState::eq_active))) << "eq_active";
  EXPECT_FALSE(SameTrace(run.rest, without(&SimState::plastic))) << "plastic";
}

TEST(SimulationState, AnEqActiveOtherThanZeroOrOneIsRefusedAndChangesNothing) {
  Simulation sim = Simulation::LoadFromString(kMujoco4StateXml);
  StepWithCommands(&sim, 10);
  const SimState before = sim.GetState();
  SimState s = before;
  s.eq_active = {0.5};
  s.qpos[0] = 1;
  try {
    sim.SetState(s);
    FAIL() << "expected an Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("eq_active[0] is 0.5; expected 0 or 1"), std::string::npos)
        << e.what();
  }
  EXPECT_EQ(sim.GetState().qpos, before.qpos);
  EXPECT_EQ(sim.GetState().eq_active, before.eq_active);
}

}  // namespace
}  // namespace penumbra
