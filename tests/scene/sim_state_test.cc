// the state table (scene/sim_state.h): one row per SimState vector in member order, sizes from
// the model's dimensions, and the loops every copy and size check uses.
#include "penumbra/scene/sim_state.h"

#include <gtest/gtest.h>

#include <set>
#include <string>
#include <type_traits>

#include "penumbra/scene/world_snapshot.h"

namespace penumbra {
namespace {

StateDims SomeDims() {
  StateDims d;
  d[StateDim::kNq] = 8;
  d[StateDim::kNv] = 7;
  d[StateDim::kNa] = 1;
  d[StateDim::kNu] = 3;
  d[StateDim::kNmocap] = 2;
  d[StateDim::kNuserdata] = 4;
  d[StateDim::kNbody] = 5;
  d[StateDim::kNumControllers] = 2;
  d[StateDim::kNhistory] = 6;
  d[StateDim::kNeq] = 3;
  d[StateDim::kNpluginstate] = 0;
  d[StateDim::kNplastic] = 2;
  return d;
}

// every vector of `s` sized for `dims`, entry k of the whole state = k + first
void FillState(SimState* s, const StateDims& dims, double first) {
  double x = first;
  ForEachStateField(
      [&](const StateFieldInfo& f, auto& v) {
        v.resize(StateFieldSize(f, dims));
        for (auto& e : v) e = static_cast<std::decay_t<decltype(e)>>(x++);
      },
      *s);
}

TEST(SimStateTable, OneRowPerMemberWithItsNameAndSize) {
  std::set<std::string> names;
  SimState s;
  for (const StateFieldInfo& f : kStateFields) {
    EXPECT_TRUE(names.insert(std::string(f.name)).second) << f.name;
    EXPECT_EQ(&StateFieldOf(f.field), &f);
  }
  EXPECT_EQ(names.size(), static_cast<size_t>(kNumStateFields));
  // the members the rows point at are SimState's, each once (by address)
  std::set<const void*> members;
  ForEachStateField([&](const StateFieldInfo&, auto& v) { members.insert(&v); }, s);
  EXPECT_EQ(members.size(), static_cast<size_t>(kNumStateFields));
  EXPECT_EQ(StateFieldOf(StateField::kQpos).name, "qpos");
  EXPECT_EQ(&(s.*StateFieldOf(StateField::kMocapQuat).f64), &s.mocap_quat);
  EXPECT_EQ(&(s.*StateFieldOf(StateField::kControllerNextUpdate).i64), &s.controller_next_update);
  EXPECT_FALSE(StateFieldOf(StateField::kControllerNextUpdate).mujoco);
  // MuJoCo 4's integration state beyond 2.2.2's: history buffers, equality switches (the one
  // flag field), plugin and plastic state
  EXPECT_EQ(&(s.*StateFieldOf(StateField::kHistory).f64), &s.history);
  EXPECT_EQ(&(s.*StateFieldOf(StateField::kEqActive).f64), &s.eq_active);
  EXPECT_EQ(&(s.*StateFieldOf(StateField::kPluginState).f64), &s.plugin_state);
  EXPECT_EQ(&(s.*StateFieldOf(StateField::kPlastic).f64), &s.plastic);
  for (const StateFieldInfo& f : kStateFields)
    EXPECT_EQ(f.flag, f.field == StateField::kEqActive) << f.name;
  EXPECT_EQ(StateFieldOf(StateField::kEqActive).name, "eq_active");
  EXPECT_EQ(kStateDimNames[static_cast<size_t>(StateDim::kNhistory)], "nhistory");
  EXPECT_EQ(kStateDimNames[static_cast<size_t>(StateDim::kNplastic)], "nplastic");
  const StateDims d = SomeDims();
  EXPECT_EQ(StateFieldSize(StateFieldOf(StateField::kXfrcApplied), d), 30);
  EXPECT_EQ(StateFieldSize(StateFieldOf(StateField::kMocapQuat), d), 8);
  EXPECT_EQ(StateFieldSize(StateFieldOf(StateField::kQaccWarmstart), d), 7);
  EXPECT_EQ(StateFieldSize(StateFieldOf(StateField::kHistory), d), 6);
  EXPECT_EQ(StateFieldSize(StateFieldOf(StateField::kEqActive), d), 3);
  EXPECT_EQ(StateFieldSize(StateFieldOf(StateField::kPlastic), d), 2);
}

TEST(SimStateTable, DimsAndSizeChecks) {
  const StateDims dims = SomeDims();
  SimState s;
  FillState(&s, dims, 1);
  EXPECT_EQ(StateDimsOf(s), dims);
  s.eq_active = {1, 0, 1};
  EXPECT_EQ(StateMismatch(s, dims), "");
  // a flag is 0 or 1 (MuJoCo's mjtBool): anything else is named with its index
  s.eq_active[1] = 0.5;
  EXPECT_EQ(StateMismatch(s, dims), "eq_active[1] is 0.5; expected 0 or 1");
  s.eq_active[1] = 0;
  s.history.pop_back();
  EXPECT_EQ(StateMismatch(s, dims), "history has 5 entries; expected 6");
  s.mocap_quat.pop_back();
  EXPECT_EQ(StateMismatch(s, dims), "mocap_quat has 7 entries; expected 8");
  s.qvel.push_back(0);
  // the first field in table order is named
  EXPECT_EQ(StateMismatch(s, dims), "qvel has 8 entries; expected 7");
}

TEST(SimStateTable, ASnapshotIsASimStateAndCopiesExactlyTheState) {
  const StateDims dims = SomeDims();
  WorldSnapshot snap;
  FillState(&snap, dims, 100);
  snap.step = 12;
  snap.time_sec = 0.024;
  snap.sensordata = {1, 2, 3};
  const SimState copy = snap;
  EXPECT_EQ(copy.step, 12);
  EXPECT_EQ(copy.time_sec, 0.024);
  bool same = true;
  ForEachStateField([&](const StateFieldInfo&, const auto& a, const auto& b) { same &= a == b; },
                    copy, snap);
  EXPECT_TRUE(same);
  // a copy by the table into a state of other sizes, as Simulation::GetState does
  SimState other;
  FillState(&other, StateDims{}, 0);
  ForEachStateField([](const StateFieldInfo&, auto& dst, const auto& src) { dst = src; }, other,
                    snap);
  EXPECT_EQ(StateDimsOf(other), dims);
  EXPECT_EQ(other.userdata, snap.userdata);
}

}  // namespace
}  // namespace penumbra
