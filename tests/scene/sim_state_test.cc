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
  const StateDims d = SomeDims();
  EXPECT_EQ(StateFieldSize(StateFieldOf(StateField::kXfrcApplied), d), 30);
  EXPECT_EQ(StateFieldSize(StateFieldOf(StateField::kMocapQuat), d), 8);
  EXPECT_EQ(StateFieldSize(StateFieldOf(StateField::kQaccWarmstart), d), 7);
}

TEST(SimStateTable, DimsAndSizeChecks) {
  const StateDims dims = SomeDims();
  SimState s;
  FillState(&s, dims, 1);
  EXPECT_EQ(StateDimsOf(s), dims);
  EXPECT_EQ(StateSizeMismatch(s, dims), "");
  s.mocap_quat.pop_back();
  EXPECT_EQ(StateSizeMismatch(s, dims), "mocap_quat has 7 entries; expected 8");
  s.qvel.push_back(0);
  // the first field in table order is named
  EXPECT_EQ(StateSizeMismatch(s, dims), "qvel has 8 entries; expected 7");
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
