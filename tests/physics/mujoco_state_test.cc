// the state table against MuJoCo's own definition of the state: every field physics/mujoco_state.h
// maps is the mjtState component of the same name, of the size and content mj_getState gives,
// and together they are MuJoCo's mjSTATE_INTEGRATION less the time (a new component in a later
// MuJoCo fails here until the table has it).
#include "penumbra/physics/mujoco_state.h"

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

namespace penumbra {
namespace {

// a delayed motor and a delayed sensor (history buffers), a yielding hinge spring (plastic
// state), a weld (eq_active), a mocap body, user data
constexpr char kStateComponentsModel[] =
    R"(<mujoco><option timestep="0.002"/><size nuserdata="3"/><worldbody>
  <geom name="floor" type="plane" size="3 3 0.1"/>
  <body name="arm" pos="0 0 1"><joint name="hinge" axis="0 1 0" stiffness="5" springyield="5"/>
    <geom type="capsule" fromto="0 0 0 0.4 0 0" size="0.03" mass="0.5"/></body>
  <body name="ball" pos="1 0 0.5"><freejoint/><geom type="sphere" size="0.1"/></body>
  <body name="target" mocap="true" pos="0 1 1"><geom type="box" size="0.1 0.1 0.1"
    contype="0" conaffinity="0"/></body>
  </worldbody>
  <equality><weld name="hold" body1="ball"/></equality>
  <actuator><motor name="m" joint="hinge" nsample="10" delay="0.02"/>
    <position name="p" joint="hinge" kp="1" timeconst="0.05"/></actuator>
  <sensor><jointpos joint="hinge" nsample="5" delay="0.006"/></sensor></mujoco>)";

// the mjtState component each mapped field is
mjtState MujocoComponentOf(StateField f) {
  switch (f) {
    case StateField::kQpos:
      return mjSTATE_QPOS;
    case StateField::kQvel:
      return mjSTATE_QVEL;
    case StateField::kAct:
      return mjSTATE_ACT;
    case StateField::kCtrl:
      return mjSTATE_CTRL;
    case StateField::kQaccWarmstart:
      return mjSTATE_WARMSTART;
    case StateField::kQfrcApplied:
      return mjSTATE_QFRC_APPLIED;
    case StateField::kXfrcApplied:
      return mjSTATE_XFRC_APPLIED;
    case StateField::kMocapPos:
      return mjSTATE_MOCAP_POS;
    case StateField::kMocapQuat:
      return mjSTATE_MOCAP_QUAT;
    case StateField::kUserdata:
      return mjSTATE_USERDATA;
    case StateField::kHistory:
      return mjSTATE_HISTORY;
    case StateField::kEqActive:
      return mjSTATE_EQ_ACTIVE;
    case StateField::kPluginState:
      return mjSTATE_PLUGIN;
    case StateField::kPlastic:
      return mjSTATE_PLASTIC;
    case StateField::kControllerNextUpdate:
      break;
  }
  return mjSTATE_TIME;
}

struct StateModelAndData {
  std::unique_ptr<mjModel, void (*)(mjModel*)> m{nullptr, mj_deleteModel};
  std::unique_ptr<mjData, void (*)(mjData*)> d{nullptr, mj_deleteData};
};

StateModelAndData LoadStateModel() {
  StateModelAndData md;
  char error[1000] = "";
  std::unique_ptr<mjSpec, void (*)(mjSpec*)> spec(
      mj_parseXMLString(kStateComponentsModel, nullptr, error, sizeof(error)), mj_deleteSpec);
  EXPECT_TRUE(spec) << error;
  if (!spec) return md;
  md.m.reset(mj_compile(spec.get(), nullptr));
  EXPECT_TRUE(md.m) << mjs_getError(spec.get());
  if (md.m) md.d.reset(mj_makeData(md.m.get()));
  return md;
}

// a few hundred steps with commands, the weld off half way: every component has values
void StepStateModel(const mjModel* m, mjData* d) {
  for (int k = 0; k < 300; ++k) {
    d->ctrl[0] = 4 * std::sin(0.05 * k);
    d->ctrl[1] = 0.3;
    d->mocap_pos[0] = 0.001 * k;
    d->userdata[k % 3] = k;
    d->xfrc_applied[6 * 1 + 3] = 0.1;
    if (k == 150) d->eq_active[0] = 0;
    mj_step(m, d);
  }
}

TEST(MujocoState, EachFieldIsMujocosComponentAndTogetherTheyAreItsIntegrationState) {
  StateModelAndData md = LoadStateModel();
  ASSERT_TRUE(md.d);
  const mjModel* m = md.m.get();
  mjData* d = md.d.get();
  StepStateModel(m, d);
  const StateDims dims = MujocoStateDims(m, 0);
  EXPECT_GT(dims[StateDim::kNhistory], 0);
  EXPECT_EQ(dims[StateDim::kNeq], 1);
  EXPECT_EQ(dims[StateDim::kNplastic], 1);
  EXPECT_EQ(dims[StateDim::kNpluginstate], 0);  // no plugin with state ships for a test here

  int64_t sum = 0;
  for (const StateFieldInfo& f : kStateFields) {
    if (!f.mujoco) continue;
    const mjtState c = MujocoComponentOf(f.field);
    ASSERT_NE(c, mjSTATE_TIME) << f.name;
    const int64_t n = StateFieldSize(f, dims);
    EXPECT_EQ(n, mj_stateSize(m, c)) << f.name;
    sum += n;
    // the values, as MuJoCo gives them (mjtBool as 0 / 1 in its mjtNum state too)
    std::vector<mjtNum> theirs(static_cast<size_t>(mj_stateSize(m, c)));
    mj_getState(m, d, theirs.data(), c);
    std::vector<double> ours(static_cast<size_t>(n));
    ReadMujocoState(d, f.field, ours);
    EXPECT_EQ(ours, theirs) << f.name;
  }
  EXPECT_EQ(sum, mj_stateSize(m, mjSTATE_INTEGRATION) - mj_stateSize(m, mjSTATE_TIME));
}

TEST(MujocoState, WriteAndCopyCarryEveryFieldToAnotherData) {
  StateModelAndData a = LoadStateModel(), b = LoadStateModel();
  ASSERT_TRUE(a.d && b.d);
  const mjModel* m = a.m.get();
  StepStateModel(m, a.d.get());
  const StateDims dims = MujocoStateDims(m, 0);
  StateModelAndData c = LoadStateModel();
  ASSERT_TRUE(c.d);
  for (const StateFieldInfo& f : kStateFields) {
    if (!f.mujoco) continue;
    std::vector<double> v(static_cast<size_t>(StateFieldSize(f, dims)));
    ReadMujocoState(a.d.get(), f.field, v);
    WriteMujocoState(b.d.get(), f.field, v);
    CopyMujocoState(a.d.get(), c.d.get(), f.field, StateFieldSize(f, dims));
  }
  // all of MuJoCo's integration state but the time is now a's, in both
  const int n = static_cast<int>(mj_stateSize(m, mjSTATE_INTEGRATION));
  std::vector<mjtNum> sa(n), sb(n), sc(n);
  b.d->time = c.d->time = a.d->time;
  mj_getState(m, a.d.get(), sa.data(), mjSTATE_INTEGRATION);
  mj_getState(m, b.d.get(), sb.data(), mjSTATE_INTEGRATION);
  mj_getState(m, c.d.get(), sc.data(), mjSTATE_INTEGRATION);
  EXPECT_EQ(sb, sa);
  EXPECT_EQ(sc, sa);
  EXPECT_EQ(b.d->eq_active[0], 0);
}

}  // namespace
}  // namespace penumbra
