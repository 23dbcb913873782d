// Simulation: snapshots against MuJoCo ground truth, determinism, divergence and
// error reporting, warnings, controller scheduling and the state they see.

#include "penumbra/physics/simulation.h"

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "common/temp_dir.h"
#include "penumbra/core/error.h"
#include "penumbra/physics/mujoco_runtime.h"

namespace penumbra {
namespace {

// a free-falling box, a 2-link arm on hinges and a mocap-free static geom
constexpr const char* kArmXml = R"(
<mujoco model="arm">
  <option timestep="0.002"/>
  <worldbody>
    <geom name="floor" type="plane" size="3 3 0.1"/>
    <body name="box" pos="0.5 0.5 1" euler="10 20 30">
      <freejoint name="box_free"/>
      <geom type="box" size="0.1 0.05 0.08"/>
    </body>
    <body name="upper" pos="0 0 1.5">
      <joint name="shoulder" type="hinge" axis="0 1 0" damping="0.1"/>
      <geom type="capsule" fromto="0 0 0 0.4 0 0" size="0.04"/>
      <body name="lower" pos="0.4 0 0">
        <joint name="elbow" type="hinge" axis="0 1 0" damping="0.1"/>
        <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03"/>
        <site name="tip" pos="0.3 0 0"/>
      </body>
    </body>
  </worldbody>
  <actuator>
    <motor name="shoulder_motor" joint="shoulder" gear="1"/>
    <motor name="elbow_motor" joint="elbow" gear="1"/>
  </actuator>
  <sensor>
    <jointpos name="elbow_pos" joint="elbow"/>
  </sensor>
</mujoco>)";

// calls a function at each update and records the update times
class LambdaController final : public Controller {
 public:
  using Fn = std::function<void(const ControlInput&, std::span<double>)>;
  LambdaController(double rate_hz, std::vector<NameRequirement> names, Fn fn)
      : Controller({"test.yaml", 7, "robots[r].controller"}),
        rate_(rate_hz),
        names_(std::move(names)),
        fn_(std::move(fn)) {}
  std::string type() const override { return "lambda"; }
  double rate_hz() const override { return rate_; }
  std::vector<NameRequirement> RequiredNames() const override { return names_; }
  void Reset() override {}  // records over the whole run
  void Compute(const ControlInput& in, std::span<double> ctrl) override {
    times.push_back(in.time_sec());
    if (fn_) fn_(in, ctrl);
  }
  std::vector<double> times;
  std::vector<int> ids;

 protected:
  void OnInitialize(const ModelInfo&, const std::vector<int>& resolved) override { ids = resolved; }

 private:
  double rate_;
  std::vector<NameRequirement> names_;
  Fn fn_;
};

TEST(Simulation, SnapshotPosesMatchMujocoKinematics) {
  Simulation sim = Simulation::LoadFromString(kArmXml);
  sim.ctrl()[0] = 0.5;
  sim.ctrl()[1] = -0.3;

  char err[512] = "";
  // ground truth: MuJoCo's own kinematics for the same qpos
  const std::string path = penumbra::testing::ProcessTempDir() + "/arm.xml";
  std::ofstream(path) << kArmXml;
  mjModel* m = mj_loadXML(path.c_str(), nullptr, err, sizeof(err));
  ASSERT_NE(m, nullptr) << err;
  mjData* d = mj_makeData(m);

  for (int i = 0; i < 300; ++i) sim.Step();
  const WorldSnapshot snap = sim.Snapshot();
  ASSERT_EQ(static_cast<int>(snap.qpos.size()), m->nq);
  std::memcpy(d->qpos, snap.qpos.data(), sizeof(double) * m->nq);
  mj_kinematics(m, d);

  EXPECT_EQ(snap.step, 300);
  EXPECT_NEAR(snap.time_sec, 300 * 0.002, 1e-12);
  ASSERT_EQ(static_cast<int>(snap.X_WB.size()), m->nbody);
  for (int b = 0; b < m->nbody; ++b) {
    for (int k = 0; k < 3; ++k) EXPECT_EQ(snap.X_WB[b].translation()[k], d->xpos[3 * b + k]) << b;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(snap.X_WB[b].linear()(r, c), d->xmat[9 * b + 3 * r + c], 1e-12) << b;
  }
  // the box has fallen and the arm has swung
  EXPECT_LT(snap.X_WB[sim.scene().FindBody("box")].translation().z(), 0.7);
  EXPECT_GT(std::abs(snap.qpos[7]), 0.01);
  mj_deleteData(d);
  mj_deleteModel(m);
}

// a pose snapshot (what cameras read) has the full snapshot's poses bit for bit and no
// sensor ground truth; taking either kind never perturbs the trajectory (next test).
TEST(Simulation, PoseSnapshotsHaveTheFullSnapshotsPoses) {
  Simulation sim = Simulation::LoadFromString(kArmXml);
  sim.ctrl()[0] = 0.5;
  for (int i = 0; i < 500; ++i) sim.Step();  // 1 s: the box has landed
  const WorldSnapshot full = sim.Snapshot(Simulation::SnapshotContent::kFull);
  WorldSnapshot poses = full;  // reused storage: the sensor fields must be cleared
  sim.Snapshot(&poses, Simulation::SnapshotContent::kPoses);
  EXPECT_EQ(poses.time_sec, full.time_sec);
  EXPECT_EQ(poses.step, full.step);
  EXPECT_EQ(poses.qpos, full.qpos);
  EXPECT_EQ(poses.qvel, full.qvel);
  ASSERT_EQ(poses.X_WB.size(), full.X_WB.size());
  for (size_t b = 0; b < full.X_WB.size(); ++b)
    EXPECT_TRUE(poses.X_WB[b].matrix() == full.X_WB[b].matrix()) << b;
  EXPECT_EQ(poses.light_position_W, full.light_position_W);
  EXPECT_EQ(poses.light_direction_W, full.light_direction_W);
  ASSERT_EQ(poses.X_W_mjcam.size(), full.X_W_mjcam.size());
  EXPECT_FALSE(full.sensordata.empty());
  EXPECT_FALSE(full.V_WB.empty());
  EXPECT_FALSE(full.contacts.empty());  // the box rests on the floor
  EXPECT_TRUE(poses.sensordata.empty());
  EXPECT_TRUE(poses.V_WB.empty());
  EXPECT_TRUE(poses.contacts.empty());
}

TEST(Simulation, MatchesBareMjStepBitForBitAndIsDeterministic) {
  const std::string path = penumbra::testing::ProcessTempDir() + "/arm_bare.xml";
  std::ofstream(path) << kArmXml;
  char err[512] = "";
  mjModel* m = mj_loadXML(path.c_str(), nullptr, err, sizeof(err));
  ASSERT_NE(m, nullptr) << err;
  mjData* d = mj_makeData(m);
  d->ctrl[0] = 0.7;

  Simulation a = Simulation::LoadFromFile(path);
  Simulation b = Simulation::LoadFromFile(path);
  a.ctrl()[0] = 0.7;
  b.ctrl()[0] = 0.7;
  WorldSnapshot scratch;
  for (int i = 0; i < 500; ++i) {
    a.Step();
    b.Step();
    mj_step(m, d);
    // snapshots of either kind must not perturb the trajectory
    b.Snapshot(&scratch,
               i % 2 ? Simulation::SnapshotContent::kFull : Simulation::SnapshotContent::kPoses);
    ASSERT_EQ(0, std::memcmp(a.qpos().data(), b.qpos().data(), sizeof(double) * m->nq)) << i;
    ASSERT_EQ(0, std::memcmp(a.qvel().data(), b.qvel().data(), sizeof(double) * m->nv)) << i;
    ASSERT_EQ(0, std::memcmp(a.qpos().data(), d->qpos, sizeof(double) * m->nq)) << i;
  }
  mj_deleteData(d);
  mj_deleteModel(m);
}

TEST(Simulation, ControlledRunsAreBitIdentical) {
  auto run = [] {
    Simulation sim = Simulation::LoadFromString(kArmXml);
    sim.AddController(std::make_unique<LambdaController>(
        100, std::vector<NameRequirement>{{ModelObject::kActuator, "shoulder_motor", "a"}},
        [](const ControlInput& in, std::span<double> ctrl) {
          ctrl[0] = -2.0 * in.qpos()[7] - 0.5 * in.qvel()[6] + std::sin(3 * in.time_sec());
        }));
    std::vector<double> traj;
    for (int i = 0; i < 400; ++i) {
      sim.Step();
      traj.insert(traj.end(), sim.qpos().begin(), sim.qpos().end());
    }
    return traj;
  };
  const std::vector<double> a = run(), b = run();
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(0, std::memcmp(a.data(), b.data(), sizeof(double) * a.size()));
}

TEST(Simulation, TimestepOverrideAndValidation) {
  Simulation sim = Simulation::LoadFromString(kArmXml, 0.001);
  EXPECT_EQ(sim.timestep(), 0.001);
  EXPECT_EQ(sim.model_info().timestep_sec, 0.001);
  for (int i = 0; i < 10; ++i) sim.Step();
  EXPECT_NEAR(sim.time(), 0.01, 1e-15);
  EXPECT_EQ(sim.step_count(), 10);
  EXPECT_THROW(Simulation::LoadFromString(kArmXml, 0.0), ConfigError);
  EXPECT_THROW(Simulation::LoadFromString(kArmXml, std::nan("")), ConfigError);
}

TEST(Simulation, LoaderErrorsNameFileAndLine) {
  const std::string bad =
      "<mujoco>\n<worldbody>\n<geom type=\"sphere\" sizze=\"1\"/>\n</worldbody>\n</mujoco>";
  try {
    Simulation::LoadFromString(bad);
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.line(), 3);
    EXPECT_EQ(e.file(), "<string>");
    EXPECT_NE(std::string(e.what()).find("sizze"), std::string::npos) << e.what();
  }
  const std::string path = penumbra::testing::ProcessTempDir() + "/bad_model.xml";
  std::ofstream(path) << bad;
  try {
    Simulation::LoadFromFile(path);
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.file(), path);
    EXPECT_EQ(e.line(), 3);
  }
  EXPECT_THROW(Simulation::LoadFromFile("/nonexistent/model.xml"), ConfigError);
}

TEST(Simulation, DivergenceThrowsWithTimeAndBody) {
  // a stiff spring integrated with a far too large timestep: explicit integration blows up
  const char* xml = R"(
<mujoco>
  <option timestep="0.01" gravity="0 0 0"/>
  <worldbody>
    <body name="pendulum" pos="0 0 1">
      <joint name="spring" type="hinge" axis="0 1 0" stiffness="1e6" springref="0.1"/>
      <geom type="capsule" fromto="0 0 0 0.5 0 0" size="0.05"/>
    </body>
  </worldbody>
</mujoco>)";
  Simulation sim = Simulation::LoadFromString(xml);
  std::string msg;
  int steps = 0;
  try {
    for (; steps < 1000; ++steps) sim.Step();
  } catch (const PhysicsError& e) {
    msg = e.what();
  }
  ASSERT_FALSE(msg.empty()) << "no divergence detected";
  EXPECT_GT(steps, 1);  // it takes a few steps to blow up
  EXPECT_NE(msg.find("diverged"), std::string::npos) << msg;
  EXPECT_NE(msg.find("body 'pendulum'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("joint 'spring'"), std::string::npos) << msg;
  char expected_time[64];
  std::snprintf(expected_time, sizeof(expected_time), "t = %.6g s (step %d)", steps * 0.01,
                steps + 1);
  EXPECT_NE(msg.find(expected_time), std::string::npos) << msg << " vs " << expected_time;
  // time and step count stay at the last completed step (MuJoCo's reset set time to 0)
  EXPECT_EQ(sim.step_count(), steps);
  EXPECT_EQ(sim.time(), SimTimeOfStep(steps, 0.01));
  // the state was reset by MuJoCo: no silent continuation
  EXPECT_THROW(sim.Step(), PhysicsError);
}

TEST(Simulation, TimeComesFromTheStepCount) {
  const char* xml = R"(
<mujoco>
  <option timestep="0.002"/>
  <worldbody>
    <body pos="0 0 1"><freejoint/><geom type="sphere" size="0.1"/></body>
  </worldbody>
</mujoco>)";
  Simulation sim = Simulation::LoadFromString(xml);
  double controller_time = -1;
  sim.AddController(std::make_unique<LambdaController>(
      0, std::vector<NameRequirement>{},
      [&](const ControlInput& in, std::span<double>) { controller_time = in.time_sec(); }));
  for (int n = 1; n <= 5000; ++n) {
    const double before = sim.time();
    sim.Step();
    ASSERT_EQ(controller_time, before);  // controllers see the same time
    ASSERT_EQ(sim.time(), SimTimeOfStep(n, 0.002)) << n;
    // a 10 Hz frame every 50 steps: floor(t * 10) is the frame index (summed time gave
    // 3.999999999999781 at step 2000)
    if (n % 50 == 0) {
      ASSERT_EQ(static_cast<int64_t>(std::floor(sim.time() * 10)), n / 50) << n;
    }
  }
  EXPECT_EQ(sim.Snapshot().time_sec, SimTimeOfStep(5000, 0.002));
}

TEST(Simulation, HugeGearDivergenceNamesBody) {
  const char* xml = R"(
<mujoco>
  <worldbody>
    <body name="arm"><joint name="hinge" axis="0 1 0"/>
      <geom type="capsule" fromto="0 0 0 1 0 0" size="0.05"/></body>
  </worldbody>
  <actuator><motor name="m" joint="hinge" gear="1e14"/></actuator>
</mujoco>)";
  Simulation sim = Simulation::LoadFromString(xml);
  double switched_on = -1;
  sim.AddController(std::make_unique<LambdaController>(
      0, std::vector<NameRequirement>{}, [&](const ControlInput& in, std::span<double> ctrl) {
        ctrl[0] = in.time_sec() >= 0.05 ? 1 : 0;
        if (ctrl[0] == 1 && switched_on < 0) switched_on = in.time_sec();
      }));
  try {
    for (int i = 0; i < 100; ++i) sim.Step();
    FAIL() << "expected PhysicsError";
  } catch (const PhysicsError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("qacc"), std::string::npos) << msg;
    EXPECT_NE(msg.find("body 'arm'"), std::string::npos) << msg;
    char when[64];
    std::snprintf(when, sizeof(when), "t = %.6g s", switched_on);
    EXPECT_GT(switched_on, 0.04);
    EXPECT_NE(msg.find(when), std::string::npos) << msg << " vs " << when;
  }
}

TEST(Simulation, NonFiniteCtrlFromControllerThrows) {
  Simulation sim = Simulation::LoadFromString(kArmXml);
  sim.AddController(std::make_unique<LambdaController>(
      50, std::vector<NameRequirement>{}, [](const ControlInput& in, std::span<double> ctrl) {
        ctrl[1] = in.time_sec() >= 0.1 ? std::nan("") : 0.0;
      }));
  try {
    for (int i = 0; i < 100; ++i) sim.Step();
    FAIL() << "expected PhysicsError";
  } catch (const PhysicsError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("t = 0.1 s (step 51)"), std::string::npos) << msg;
    EXPECT_NE(msg.find("actuator 'elbow_motor'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("body 'lower'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("robots[r].controller"), std::string::npos) << msg;
  }
}

TEST(Simulation, MujocoErrorsBecomePhysicsErrorsNotExit) {
  // a tiny arena (MuJoCo's stack and contacts) cannot hold the contact solver's work arrays
  const char* xml = R"(
<mujoco><size memory="4K"/>
  <worldbody><geom type="plane" size="1 1 1"/>
    <body name="a" pos="0 0 0.1"><freejoint/><geom type="box" size=".1 .1 .1"/></body>
    <body name="b" pos="0.1 0 0.4"><freejoint/><geom type="box" size=".1 .1 .1"/></body>
  </worldbody></mujoco>)";
  Simulation sim = Simulation::LoadFromString(xml);
  try {
    for (int i = 0; i < 500; ++i) sim.Step();
    FAIL() << "expected PhysicsError";
  } catch (const PhysicsError& e) {
    EXPECT_NE(std::string(e.what()).find("stack overflow"), std::string::npos) << e.what();
  }
}

TEST(Simulation, NonFatalWarningsAreCollectedWithTime) {
  const char* xml = R"(
<mujoco><size memory="16K"/>
  <worldbody><geom type="plane" size="1 1 1"/>
    <body name="a" pos="0 0 0.1"><freejoint/><geom type="box" size=".1 .1 .1"/></body>
    <body name="b" pos="0.1 0 0.4"><freejoint/><geom type="box" size=".1 .1 .1"/></body>
  </worldbody></mujoco>)";
  Simulation sim = Simulation::LoadFromString(xml);
  sim.TakeWarnings();  // drop loader messages
  // the upper box lands on the lower after ~0.14 s: more constraints than the arena holds
  for (int i = 0; i < 400; ++i) sim.Step();
  const std::vector<std::string> w = sim.TakeWarnings();
  ASSERT_FALSE(w.empty());
  EXPECT_NE(w[0].find("Insufficient arena memory"), std::string::npos) << w[0];
  EXPECT_NE(w[0].find("t = 0."), std::string::npos) << w[0];
  EXPECT_TRUE(sim.TakeWarnings().empty());
}

TEST(Simulation, KeyframeReachesUnnamedFreeJointsAndActuatorsOfItsModel) {
  // two composed models: "a/" with Menagerie's unnamed <freejoint/> and an unnamed actuator
  // with activation dynamics, placed before a stateless one; "b/" named, left alone
  const char* xml = R"(
<mujoco>
  <worldbody>
    <body name="a/trunk" pos="0 0 0.5"><freejoint/><geom type="box" size=".1 .1 .1"/>
      <body name="a/leg"><joint name="a/hip" type="hinge"/><geom type="capsule" size=".02 .1"/></body>
    </body>
    <body name="b/trunk" pos="1 0 0.5"><freejoint name="b/root"/><geom type="box" size=".1 .1 .1"/></body>
  </worldbody>
  <actuator>
    <general joint="a/hip" dyntype="filter" dynprm="0.1"/>
    <motor name="b/none" joint="b/root" gear="0 0 1 0 0 0"/>
  </actuator>
  <keyframe>
    <key name="a/home" qpos="0.1 0 0.27 1 0 0 0 0.3 1 0 0.5 1 0 0 0" ctrl="0.7 0" act="0.4"/>
  </keyframe>
</mujoco>)";
  Simulation sim = Simulation::LoadFromString(xml);
  sim.ApplyKeyframe("a/home", "a/", "models[a].initial_keyframe");
  const SimState s = sim.GetState();
  ASSERT_EQ(s.qpos.size(), 15u);
  EXPECT_EQ(s.qpos[0], 0.1);
  EXPECT_EQ(s.qpos[2], 0.27) << "the unnamed free joint of a/trunk takes the key's height";
  EXPECT_EQ(s.qpos[7], 0.3);
  EXPECT_EQ(s.qpos[8], 1.0) << "b/'s free joint keeps its reference position";
  EXPECT_EQ(s.qpos[10], 0.5);
  EXPECT_EQ(s.ctrl[0], 0.7);
  ASSERT_EQ(s.act.size(), 1u);
  EXPECT_EQ(s.act[0], 0.4) << "the activation of a/'s unnamed filter actuator";
}

TEST(Simulation, MultiInputActuatorsAreRefusedNamingTheActuator) {
  // MuJoCo 4's <orientation> servo takes 3 controls and gives 3 forces
  const char* xml = R"(
<mujoco><worldbody>
  <body><joint name="b" type="ball"/><geom size=".1"/></body>
  <body pos="1 0 0"><joint name="h"/><geom size=".1"/></body>
</worldbody>
<actuator><motor joint="h"/><orientation name="wrist" joint="b" kp="10"/></actuator></mujoco>)";
  try {
    Simulation::LoadFromString(xml);
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "actuator wrist");
    EXPECT_NE(std::string(e.what()).find("takes 3 controls and gives 3 forces"), std::string::npos)
        << e.what();
  }
}

TEST(Simulation, MujocosOwnPluginsLoad) {
  // MuJoCo's PID actuator plugin, from the plugin folder the wheel ships beside libmujoco
  ASSERT_FALSE(MujocoPluginDir().empty()) << "the mujoco wheel ships mujoco/plugin/";
  const char* xml = R"(
<mujoco><option gravity="0 0 0"/>
  <extension><plugin plugin="mujoco.pid"><instance name="pid1">
    <config key="kp" value="40"/><config key="ki" value="4"/><config key="kd" value="4"/>
  </instance></plugin></extension>
  <worldbody><body><joint name="j" type="hinge"/>
    <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03"/></body></worldbody>
  <actuator><plugin name="servo" joint="j" plugin="mujoco.pid" instance="pid1" actdim="1"/>
  </actuator></mujoco>)";
  Simulation sim = Simulation::LoadFromString(xml);
  sim.ctrl()[0] = 0.5;
  for (int i = 0; i < 2000; ++i) sim.Step();
  EXPECT_NEAR(sim.GetState().qpos[0], 0.5, 0.01) << "the PID holds the joint at its setpoint";
}

TEST(Simulation, ControllersRunAtTheirRateOnSimTime) {
  Simulation sim = Simulation::LoadFromString(kArmXml, 0.003);
  auto c30 = std::make_unique<LambdaController>(30, std::vector<NameRequirement>{}, nullptr);
  auto c0 = std::make_unique<LambdaController>(0, std::vector<NameRequirement>{}, nullptr);
  auto c1000 = std::make_unique<LambdaController>(1000, std::vector<NameRequirement>{}, nullptr);
  LambdaController *p30 = c30.get(), *p0 = c0.get(), *p1000 = c1000.get();
  sim.AddController(std::move(c30));
  sim.AddController(std::move(c0));
  sim.AddController(std::move(c1000));
  const int n = 1000;  // 3 s
  for (int i = 0; i < n; ++i) sim.Step();
  EXPECT_EQ(p0->times.size(), static_cast<size_t>(n));
  EXPECT_EQ(p1000->times.size(), static_cast<size_t>(n));  // faster than physics: every step
  // update k at the first step whose time is >= k / 30
  ASSERT_EQ(p30->times.size(), 90u);
  for (size_t k = 0; k < p30->times.size(); ++k) {
    const double want = std::ceil((k / 30.0) / 0.003 - 1e-9) * 0.003;
    EXPECT_NEAR(p30->times[k], want, 1e-9) << k;
  }
}

class ControllerStateTest : public ::testing::TestWithParam<const char*> {};

// every integrator: Euler and implicit split the step around the controllers (mj_step1 /
// mj_step2), RK4 runs mj_step1 for them and then a full mj_step
INSTANTIATE_TEST_SUITE_P(Integrators, ControllerStateTest,
                         ::testing::Values("Euler", "implicit", "RK4"));

TEST_P(ControllerStateTest, ControllersSeeCurrentStateAndDerivedQuantities) {
  std::string xml = kArmXml;
  const std::string opt = "<option timestep=\"0.002\"/>";
  xml.replace(xml.find(opt), opt.size(),
              std::string("<option timestep=\"0.002\" integrator=\"") + GetParam() + "\"/>");
  Simulation sim = Simulation::LoadFromString(xml);
  int checks = 0;
  sim.AddController(std::make_unique<LambdaController>(
      0,
      std::vector<NameRequirement>{{ModelObject::kBody, "box", "b"},
                                   {ModelObject::kBody, "lower", "l"},
                                   {ModelObject::kSensor, "elbow_pos", "s"}},
      [&checks](const ControlInput& in, std::span<double> ctrl) {
        const ModelInfo& mi = in.model();
        const int box = mi.Find(ModelObject::kBody, "box");
        const int lower = mi.Find(ModelObject::kBody, "lower");
        // body pose belongs to this instant's qpos (free joint: x y z qw qx qy qz)
        const Pose X = in.X_WB(box);
        for (int k = 0; k < 3; ++k) ASSERT_EQ(X.translation()[k], in.qpos()[k]);
        // position-stage sensors are current
        ASSERT_EQ(in.sensordata()[0], in.qpos()[mi.joints[2].qpos_adr]);
        // twist = J qvel at the body origin
        Eigen::Matrix<double, 6, Eigen::Dynamic> J;
        const Pose X_lower = in.X_WB(lower);
        in.Jacobian(lower, X_lower.translation(), &J);
        Eigen::VectorXd qvel(in.qvel().size());
        for (int i = 0; i < qvel.size(); ++i) qvel[i] = in.qvel()[i];
        const Twist V = in.V_WB(lower);
        ASSERT_LT((J * qvel - V).norm(), 1e-9 * (1 + V.norm()));
        ctrl[0] = 0.3;
        ctrl[1] = -0.2;
        ++checks;
      }));
  for (int i = 0; i < 200; ++i) sim.Step();
  EXPECT_EQ(checks, 200);
  EXPECT_GT(std::abs(sim.qvel()[7]), 0.0);
}

TEST(Simulation, MissingControllerNamesAreAllListedAtLoad) {
  Simulation sim = Simulation::LoadFromString(kArmXml);
  auto c = std::make_unique<LambdaController>(
      10,
      std::vector<NameRequirement>{{ModelObject::kJoint, "shoulder", "shoulder_joint"},
                                   {ModelObject::kJoint, "wrist", "wrist_joint"},
                                   {ModelObject::kActuator, "gripper", "gripper_actuator"},
                                   {ModelObject::kBody, "hand", "hand_body"}},
      nullptr);
  try {
    sim.AddController(std::move(c));
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(e.file(), "test.yaml");
    EXPECT_EQ(e.line(), 7);
    EXPECT_NE(msg.find("3 names not found"), std::string::npos) << msg;
    EXPECT_NE(msg.find("wrist_joint: joint 'wrist'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("gripper_actuator: actuator 'gripper'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("hand_body: body 'hand'"), std::string::npos) << msg;
    EXPECT_EQ(msg.find("joint 'shoulder'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("'elbow_motor'"), std::string::npos) << msg;  // existing names hint
  }
  EXPECT_EQ(sim.num_controllers(), 0);
}

TEST(Simulation, ModelInfoIndexes) {
  Simulation sim = Simulation::LoadFromString(kArmXml);
  const ModelInfo& mi = sim.model_info();
  EXPECT_EQ(mi.nq, 7 + 2);
  EXPECT_EQ(mi.nv, 6 + 2);
  EXPECT_EQ(mi.nu, 2);
  const int elbow = mi.Find(ModelObject::kJoint, "elbow");
  ASSERT_GE(elbow, 0);
  EXPECT_EQ(mi.joints[elbow].qpos_adr, 8);
  EXPECT_EQ(mi.joints[elbow].dof_adr, 7);
  EXPECT_EQ(mi.body_names[mi.joints[elbow].body], "lower");
  EXPECT_EQ(mi.actuators[mi.Find(ModelObject::kActuator, "elbow_motor")].joint, elbow);
  EXPECT_EQ(mi.joints[mi.Find(ModelObject::kJoint, "box_free")].type, JointInfo::Type::kFree);
  EXPECT_EQ(mi.site_body[mi.Find(ModelObject::kSite, "tip")], mi.Find(ModelObject::kBody, "lower"));
  EXPECT_EQ(mi.Find(ModelObject::kBody, "nope"), -1);
}

}  // namespace
}  // namespace penumbra
