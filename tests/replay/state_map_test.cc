// StateMap: a logged state copied by name onto a replay model whose ids and addresses moved
// (NPC mocap bodies added or removed), and the errors for a model that changed what moves.
#include "penumbra/replay/state_map.h"

#include <gtest/gtest.h>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

RunLogJoint Joint(std::string name, std::string type, int qpos_adr, int qvel_adr) {
  RunLogJoint j;
  j.name = std::move(name);
  j.type = std::move(type);
  j.qpos_width = j.type == "free" ? 7 : j.type == "ball" ? 4 : 1;
  j.qvel_width = j.type == "free" ? 6 : j.type == "ball" ? 3 : 1;
  j.qpos_adr = qpos_adr;
  j.qvel_adr = qvel_adr;
  return j;
}

// a robot (free base + two hinges, two motors of which the second is stateful), one NPC
RunLogLayout RecordedLayout() {
  RunLogLayout l;
  l.joints = {Joint("r/base", "free", 0, 0), Joint("r/hip", "hinge", 7, 6),
              Joint("r/knee", "hinge", 8, 7)};
  l.nq = 9, l.nv = 8, l.nu = 2, l.na = 1, l.nuserdata = 1;
  l.actuator_names = {"r/hip_motor", "r/knee_filter"};
  l.mocap_body_names = {"npc0"};
  l.nmocap = 1;
  l.body_names = {"world", "r/trunk", "r/thigh", "r/calf", "npc0"};
  l.nbody = 5;
  return l;
}

StepRecord RecordOf(const RunLogLayout& l, int64_t step) {
  StepRecord r;
  r.step = step;
  r.time_sec = 0.002 * step;
  const auto fill = [](std::vector<double>* v, size_t n, double base) {
    v->resize(n);
    for (size_t i = 0; i < n; ++i) (*v)[i] = base + static_cast<double>(i);
  };
  fill(&r.qpos, l.nq, 100);
  fill(&r.qvel, l.nv, 200);
  fill(&r.act, l.na, 300);
  fill(&r.ctrl, l.nu, 400);
  fill(&r.qacc_warmstart, l.nv, 500);
  fill(&r.qfrc_applied, l.nv, 600);
  fill(&r.xfrc_applied, 6 * l.nbody, 700);
  fill(&r.mocap_pos, 3 * l.nmocap, 800);
  fill(&r.mocap_quat, 4 * l.nmocap, 900);
  fill(&r.userdata, l.nuserdata, 1000);
  fill(&r.history, l.nhistory, 1100);
  r.eq_active.assign(l.neq, 0);
  fill(&r.plugin_state, l.npluginstate, 1200);
  fill(&r.plastic, l.nplastic, 1300);
  return r;
}

SimState EmptyState(const RunLogLayout& l) {
  SimState s;
  s.qpos.assign(l.nq, -1);
  s.qvel.assign(l.nv, -1);
  s.act.assign(l.na, -1);
  s.ctrl.assign(l.nu, -1);
  s.qacc_warmstart.assign(l.nv, -1);
  s.qfrc_applied.assign(l.nv, -1);
  s.xfrc_applied.assign(6 * l.nbody, -1);
  s.mocap_pos.assign(3 * l.nmocap, -1);
  s.mocap_quat.assign(4 * l.nmocap, -1);
  s.userdata.assign(l.nuserdata, -1);
  s.history.assign(l.nhistory, -1);
  s.eq_active.assign(l.neq, 1);
  s.plugin_state.assign(l.npluginstate, -1);
  s.plastic.assign(l.nplastic, -1);
  return s;
}

TEST(MatchNames, NamedByNameUnnamedByOrder) {
  EXPECT_EQ(MatchNames({"a", "", "b", "", "gone"}, {"", "b", "new", "a", ""}),
            (std::vector<int>{3, 0, 1, 4, -1}));
}

TEST(StateMap, TheSameLayoutCopiesEverything) {
  const RunLogLayout l = RecordedLayout();
  const StateMap map(l, l, "run.plog");
  EXPECT_TRUE(map.identity());
  EXPECT_TRUE(map.unlogged_mocap().empty());
  const StepRecord r = RecordOf(l, 42);
  SimState s = EmptyState(l);
  map.Apply(r, &s);
  EXPECT_EQ(s.step, 42);
  EXPECT_EQ(s.time_sec, r.time_sec);
  EXPECT_EQ(s.qpos, r.qpos);
  EXPECT_EQ(s.qvel, r.qvel);
  EXPECT_EQ(s.act, r.act);
  EXPECT_EQ(s.ctrl, r.ctrl);
  EXPECT_EQ(s.qacc_warmstart, r.qacc_warmstart);
  EXPECT_EQ(s.qfrc_applied, r.qfrc_applied);
  EXPECT_EQ(s.xfrc_applied, r.xfrc_applied);
  EXPECT_EQ(s.mocap_pos, r.mocap_pos);
  EXPECT_EQ(s.mocap_quat, r.mocap_quat);
  EXPECT_EQ(s.userdata, r.userdata);
}

// the replay model of an adversity preset: its NPCs' mocap bodies come first here, and bodies
// and joints are listed in another order; the logged NPC is gone
TEST(StateMap, MovedAddressesAndAddedMocapBodiesMapByName) {
  const RunLogLayout log = RecordedLayout();
  RunLogLayout m;
  m.joints = {Joint("r/knee", "hinge", 0, 0), Joint("r/base", "free", 1, 1),
              Joint("r/hip", "hinge", 8, 7)};
  m.nq = 9, m.nv = 8, m.nu = 2, m.na = 1, m.nuserdata = 1;
  m.actuator_names = {"r/hip_motor", "r/knee_filter"};
  m.mocap_body_names = {"adversity_person0", "adversity_person1"};
  m.nmocap = 2;
  m.body_names = {"world",  "adversity_person0", "r/trunk", "adversity_person1", "r/calf",
                  "r/thigh"};
  m.nbody = 6;
  const StateMap map(log, m, "run.plog");
  EXPECT_FALSE(map.identity());
  EXPECT_EQ(map.unlogged_mocap(), (std::vector<int>{0, 1}));
  EXPECT_EQ(map.dropped_mocap(), (std::vector<std::string>{"npc0"}));
  const StepRecord r = RecordOf(log, 7);
  SimState s = EmptyState(m);
  map.Apply(r, &s);
  // knee: log qpos[8] -> model qpos[0]; base: log [0, 7) -> model [1, 8); hip: log 7 -> 8
  EXPECT_EQ(s.qpos, (std::vector<double>{108, 100, 101, 102, 103, 104, 105, 106, 107}));
  EXPECT_EQ(s.qvel, (std::vector<double>{207, 200, 201, 202, 203, 204, 205, 206}));
  EXPECT_EQ(s.qacc_warmstart[0], 507);
  EXPECT_EQ(s.qfrc_applied[7], 606);
  // the mocap bodies the log lacks keep what they had (their drivers pose them)
  EXPECT_EQ(s.mocap_pos, std::vector<double>(6, -1));
  // xfrc per body name: r/trunk log 1 -> model 2, r/calf 3 -> 4, r/thigh 2 -> 5; NPCs keep
  EXPECT_EQ(s.xfrc_applied[6 * 2], 706);
  EXPECT_EQ(s.xfrc_applied[6 * 4 + 5], 700 + 6 * 3 + 5);
  EXPECT_EQ(s.xfrc_applied[6 * 5], 712);
  EXPECT_EQ(s.xfrc_applied[6 * 1], -1);
  EXPECT_EQ(s.xfrc_applied[6 * 3], -1);
}

TEST(StateMap, LoggedMocapBodiesFollowTheLogWhereverTheyAre) {
  const RunLogLayout log = RecordedLayout();
  RunLogLayout m = log;
  m.mocap_body_names = {"adversity_person0", "npc0"};
  m.nmocap = 2;
  const StateMap map(log, m, "run.plog");
  EXPECT_EQ(map.unlogged_mocap(), (std::vector<int>{0}));
  SimState s = EmptyState(m);
  map.Apply(RecordOf(log, 1), &s);
  EXPECT_EQ(s.mocap_pos, (std::vector<double>{-1, -1, -1, 800, 801, 802}));
  EXPECT_EQ(s.mocap_quat, (std::vector<double>{-1, -1, -1, -1, 900, 901, 902, 903}));
}

std::string ErrorOf(const RunLogLayout& log, const RunLogLayout& model) {
  try {
    StateMap(log, model, "/data/run.plog");
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.file(), "/data/run.plog");
    return e.what();
  }
  return "(no error)";
}

TEST(StateMap, AModelThatChangedWhatMovesIsRefusedNamingIt) {
  const RunLogLayout log = RecordedLayout();
  RunLogLayout m = log;
  m.joints.pop_back();
  m.nq = 8, m.nv = 7;
  EXPECT_NE(ErrorOf(log, m).find("no joint 'r/knee' (hinge, qpos width 1) that the log records"),
            std::string::npos)
      << ErrorOf(log, m);

  m = log;
  m.joints[1] = Joint("r/hip", "ball", 7, 6);
  EXPECT_NE(ErrorOf(log, m).find("joint 'r/hip' is ball with qpos width 4"), std::string::npos)
      << ErrorOf(log, m);

  m = log;
  m.joints.push_back(Joint("extra/slider", "slide", 9, 8));
  EXPECT_NE(ErrorOf(log, m).find("has joint 'extra/slider', which the log does not record"),
            std::string::npos)
      << ErrorOf(log, m);

  m = log;
  m.actuator_names[0] = "r/other_motor";
  EXPECT_NE(ErrorOf(log, m).find("no actuator 'r/hip_motor'"), std::string::npos)
      << ErrorOf(log, m);

  m = log;
  m.na = 0;
  EXPECT_NE(ErrorOf(log, m).find("actuator 'r/knee_filter' has no activation state"),
            std::string::npos)
      << ErrorOf(log, m);

  m = log;
  m.nuserdata = 3;
  EXPECT_NE(ErrorOf(log, m).find("3 userdata entries; the log records 1"), std::string::npos)
      << ErrorOf(log, m);
}

TEST(StateMap, ARecordOfAnotherSizeIsRefused) {
  const RunLogLayout l = RecordedLayout();
  const StateMap map(l, l, "run.plog");
  StepRecord r = RecordOf(l, 1);
  r.qvel.pop_back();
  SimState s = EmptyState(l);
  EXPECT_THROW(map.Apply(r, &s), Error);
}

// MuJoCo 4's history buffers, equality switches, plugin and plastic state: per model, copied
// whole
RunLogLayout WithMujoco4State(RunLogLayout l) {
  l.nhistory = 4;
  l.neq = 2;
  l.npluginstate = 1;
  l.nplastic = 3;
  return l;
}

TEST(StateMap, HistoryEqualitiesPluginAndPlasticStateAreCopiedWhole) {
  const RunLogLayout l = WithMujoco4State(RecordedLayout());
  const StateMap map(l, l, "run.plog");
  EXPECT_TRUE(map.identity());
  const StepRecord r = RecordOf(l, 9);
  SimState s = EmptyState(l);
  map.Apply(r, &s);
  EXPECT_EQ(s.history, (std::vector<double>{1100, 1101, 1102, 1103}));
  EXPECT_EQ(s.eq_active, (std::vector<double>{0, 0}));
  EXPECT_EQ(s.plugin_state, std::vector<double>{1200});
  EXPECT_EQ(s.plastic, (std::vector<double>{1300, 1301, 1302}));
  // the rest as before
  EXPECT_EQ(s.qpos, r.qpos);
}

// a format 1 log (MuJoCo 2.2.2) records none of them: the replay model keeps its own, and the
// layouts still count as the same (a resimulation compares only what the log holds)
TEST(StateMap, ALogWithoutThemKeepsTheReplayModelsOwn) {
  const RunLogLayout log = RecordedLayout();
  const RunLogLayout m = WithMujoco4State(log);
  const StateMap map(log, m, "run.plog");
  EXPECT_TRUE(map.identity());
  SimState s = EmptyState(m);
  map.Apply(RecordOf(log, 3), &s);
  EXPECT_EQ(s.history, std::vector<double>(4, -1));
  EXPECT_EQ(s.eq_active, std::vector<double>(2, 1));
  EXPECT_EQ(s.plugin_state, std::vector<double>(1, -1));
  EXPECT_EQ(s.plastic, std::vector<double>(3, -1));
  EXPECT_EQ(s.qvel, RecordOf(log, 3).qvel);
}

TEST(StateMap, AnotherCountOfThemThanTheLogsIsRefusedNamingIt) {
  const RunLogLayout log = WithMujoco4State(RecordedLayout());
  RunLogLayout m = log;
  m.neq = 3;
  EXPECT_NE(ErrorOf(log, m).find("the replay model's neq is 3; the log records 2"),
            std::string::npos)
      << ErrorOf(log, m);
  m = log;
  m.nhistory = 0;
  EXPECT_NE(ErrorOf(log, m).find("the replay model's nhistory is 0; the log records 4"),
            std::string::npos)
      << ErrorOf(log, m);
}

// MuJoCo 4: a stateful actuator need not come last and may hold several activations (a pid
// with slew and integral, actdim 2): the same actuators copy ctrl and act whole
TEST(StateMap, TheSameActuatorsCopyEveryActivationWhereverItIs) {
  RunLogLayout l = RecordedLayout();
  l.actuator_names = {"r/pid"};  // one actuator, two activations
  l.nu = 1, l.na = 2;
  RunLogLayout m = l;
  m.mocap_body_names = {"adversity_person0", "npc0"};  // an added agent: not the same layout
  m.nmocap = 2;
  const StateMap map(l, m, "run.plog");
  EXPECT_FALSE(map.identity());
  const StepRecord r = RecordOf(l, 5);
  SimState s = EmptyState(m);
  map.Apply(r, &s);
  EXPECT_EQ(s.act, (std::vector<double>{300, 301}));
  EXPECT_EQ(s.ctrl, std::vector<double>{400});
}

}  // namespace
}  // namespace penumbra
