#pragma once
// the simulation state, written out once: `SimState` (what a bit-exact restart needs), the
// `StateField` enum of its vectors and `kStateFields`, the table every copy, comparison, size
// check and serialisation loops over (MuJoCo's own pattern: mjxmacro.h, mjtState /
// mj_stateSize / mj_stateElemPtr). the physics module maps a field to
// its mjData array with one switch (physics/mujoco_state.h); nothing else names the fields one
// by one. a snapshot (scene/world_snapshot.h) is a SimState plus what is derived from it; the
// run log's step record (runlog/run_log_format.h) is a SimState.
//
// to add a field: a member here, its enumerator, its row in kStateFields (the row's place is
// its place in a run log's step record: append, raise the log's format version and give it
// its row and dimension counts in runlog/run_log_format.h RunLogStateShapeOf), and its case in
// physics/mujoco_state.cc; a field whose size is a new model dimension also needs its
// StateDim (appended), its name in kStateDimNames and its case in MujocoStateDims.

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace penumbra {

/// everything a bit-exact restart of a Simulation needs (Simulation::GetState / SetState),
/// for MuJoCo 4: mj_step is a function of exactly these mjData fields (MuJoCo's
/// mjSTATE_INTEGRATION less time, which is the step count's: SimTimeOfStep) and of the model;
/// every other mjData field is recomputed from them by the next step's mj_forward.
/// qacc_warmstart is the constraint solver's starting point: without it the next contact solve
/// starts elsewhere and the trajectory differs in the last bits; history holds the delayed
/// actuators' and sensors' past samples, plastic the plastic deformation of joints, tendons
/// and flexes. plus penumbra's own: the step count (time is SimTimeOfStep(step, timestep)) and
/// each controller's next update (its schedule on the controllers' clock,
/// Simulation::ResetControllers).
///
/// NOT included: the controllers' own memory (waypoint index, gait phase, integrators, ...),
/// which Simulation::ResetControllers returns to its start, and the controllers' episode start.
/// SetState restores physics and the controllers' schedule only; a restart is bit-exact for a
/// simulation whose controllers keep no state between updates, or that has none. mocap
/// drivers (Simulation::AddMocapDriver) are pure functions of time and need nothing.
/// vectors are MuJoCo's, in its order and units; their sizes are in kStateFields (from the
/// model's StateDims: nq, nv, na, nu, nbody, nmocap, nuserdata, number of controllers,
/// nhistory, neq, npluginstate, nplastic).
struct SimState {
  int64_t step = 0;                    ///< steps completed since loading (0 = initial state)
  double time_sec = 0;                 ///< sim time, s (SimTimeOfStep(step, timestep))
  std::vector<double> qpos;            ///< (nq) joint positions
  std::vector<double> qvel;            ///< (nv) joint velocities
  std::vector<double> act;             ///< (na) actuator activations
  std::vector<double> ctrl;            ///< (nu) controls
  std::vector<double> qacc_warmstart;  ///< (nv) constraint solver warm start
  std::vector<double> qfrc_applied;    ///< (nv) applied generalized forces, N or N m per dof
  std::vector<double> xfrc_applied;    ///< (6 nbody) applied wrenches (torque, force), world
  std::vector<double> mocap_pos;       ///< (3 nmocap) mocap body positions, m, world frame
  std::vector<double> mocap_quat;      ///< (4 nmocap) mocap body orientations (w, x, y, z)
  std::vector<double> userdata;        ///< (nuserdata) MuJoCo user data
  /// (number of controllers) step index of each controller's next update (Controller::rate_hz)
  std::vector<int64_t> controller_next_update;
  /// (nhistory) the history buffers of actuators and sensors with nsample > 0 (delays)
  std::vector<double> history;
  /// (neq) which equality constraints are on: 1 or 0 (MuJoCo's mjtBool, as a double)
  std::vector<double> eq_active;
  std::vector<double> plugin_state;  ///< (npluginstate) the plugins' state
  std::vector<double> plastic;       ///< (nplastic) plastic deformation (springyield, flexes)
};

/// the vectors of SimState, in kStateFields order.
enum class StateField : uint8_t {
  kQpos,
  kQvel,
  kAct,
  kCtrl,
  kQaccWarmstart,
  kQfrcApplied,
  kXfrcApplied,
  kMocapPos,
  kMocapQuat,
  kUserdata,
  kControllerNextUpdate,
  kHistory,
  kEqActive,
  kPluginState,
  kPlastic,
};
/// the number of StateField values (rows of kStateFields).
inline constexpr int kNumStateFields = 15;

/// the model dimension a state vector's size is a multiple of.
enum class StateDim : uint8_t {
  kNq,              ///< MuJoCo nq: generalized coordinates
  kNv,              ///< MuJoCo nv: degrees of freedom
  kNa,              ///< MuJoCo na: actuator activations
  kNu,              ///< MuJoCo nu: actuators
  kNmocap,          ///< MuJoCo nmocap: mocap bodies
  kNuserdata,       ///< MuJoCo nuserdata
  kNbody,           ///< MuJoCo nbody: bodies including the world
  kNumControllers,  ///< controllers of the Simulation
  kNhistory,        ///< MuJoCo nhistory: entries of the history buffers
  kNeq,             ///< MuJoCo neq: equality constraints
  kNpluginstate,    ///< MuJoCo npluginstate: entries of the plugins' state
  kNplastic,        ///< MuJoCo nplastic: entries of the plastic state
};
/// the number of StateDim values.
inline constexpr int kNumStateDims = 12;
/// the names of the dimensions by StateDim, as the run log's header layout spells them.
inline constexpr std::array<std::string_view, kNumStateDims> kStateDimNames = {
    "nq",       "nv",  "na",           "nu",      "nmocap", "nuserdata", "nbody", "num_controllers",
    "nhistory", "neq", "npluginstate", "nplastic"};

/// the sizes of one model's state (counts >= 0), indexed by StateDim.
struct StateDims {
  std::array<int64_t, kNumStateDims> n{};
  /// the count of dimension `d`.
  constexpr int64_t operator[](StateDim d) const { return n[static_cast<size_t>(d)]; }
  constexpr int64_t& operator[](StateDim d) { return n[static_cast<size_t>(d)]; }
  bool operator==(const StateDims&) const = default;
};

/// one row of kStateFields: a vector of SimState, its name, its size, its member.
struct StateFieldInfo {
  StateField field;
  /// the field's name: the SimState member, the mjData array (but controller_next_update),
  /// the name in run log messages and protocol JSON.
  std::string_view name;
  StateDim dim;  ///< the dimension the size is a multiple of
  int per = 1;   ///< entries per unit of `dim` (size = per * dims[dim])
  /// the member: exactly one of f64 (double vectors) and i64 (int64 vectors) is set.
  std::vector<double> SimState::*f64 = nullptr;
  std::vector<int64_t> SimState::*i64 = nullptr;
  /// true for an mjData array (physics/mujoco_state.h maps it); false for penumbra's own.
  bool mujoco = true;
  /// true for a flag field: every entry is 0 or 1 (an mjtBool array of MuJoCo, eq_active).
  bool flag = false;
};

/// every vector of SimState, in StateField order, which is also the order of a run log's step
/// record (docs/run-log.md "Step record").
inline constexpr std::array<StateFieldInfo, kNumStateFields> kStateFields = {{
    {StateField::kQpos, "qpos", StateDim::kNq, 1, &SimState::qpos},
    {StateField::kQvel, "qvel", StateDim::kNv, 1, &SimState::qvel},
    {StateField::kAct, "act", StateDim::kNa, 1, &SimState::act},
    {StateField::kCtrl, "ctrl", StateDim::kNu, 1, &SimState::ctrl},
    {StateField::kQaccWarmstart, "qacc_warmstart", StateDim::kNv, 1, &SimState::qacc_warmstart},
    {StateField::kQfrcApplied, "qfrc_applied", StateDim::kNv, 1, &SimState::qfrc_applied},
    {StateField::kXfrcApplied, "xfrc_applied", StateDim::kNbody, 6, &SimState::xfrc_applied},
    {StateField::kMocapPos, "mocap_pos", StateDim::kNmocap, 3, &SimState::mocap_pos},
    {StateField::kMocapQuat, "mocap_quat", StateDim::kNmocap, 4, &SimState::mocap_quat},
    {StateField::kUserdata, "userdata", StateDim::kNuserdata, 1, &SimState::userdata},
    {StateField::kControllerNextUpdate, "controller_next_update", StateDim::kNumControllers, 1,
     nullptr, &SimState::controller_next_update, false},
    {StateField::kHistory, "history", StateDim::kNhistory, 1, &SimState::history},
    {StateField::kEqActive, "eq_active", StateDim::kNeq, 1, &SimState::eq_active, nullptr, true,
     true},
    {StateField::kPluginState, "plugin_state", StateDim::kNpluginstate, 1, &SimState::plugin_state},
    {StateField::kPlastic, "plastic", StateDim::kNplastic, 1, &SimState::plastic},
}};

namespace sim_state_detail {
constexpr bool TableInOrder() {
  for (int i = 0; i < kNumStateFields; ++i) {
    const StateFieldInfo& f = kStateFields[i];
    if (static_cast<int>(f.field) != i || (f.f64 == nullptr) == (f.i64 == nullptr) || f.per < 1 ||
        (f.flag && (f.f64 == nullptr || !f.mujoco)))
      return false;
  }
  return true;
}
}  // namespace sim_state_detail
static_assert(sim_state_detail::TableInOrder(),
              "kStateFields: row i must be StateField i with exactly one member pointer (a flag "
              "field: a double one of MuJoCo's)");

/// the row of `field`.
constexpr const StateFieldInfo& StateFieldOf(StateField field) {
  return kStateFields[static_cast<size_t>(field)];
}

/// the number of entries of `field` for a model of sizes `dims`.
constexpr int64_t StateFieldSize(const StateFieldInfo& field, const StateDims& dims) {
  return field.per * dims[field.dim];
}

/// calls f(info, v...) for every row of kStateFields, where v are the field's vectors of
/// `states` (SimState or a type derived from it, e.g. WorldSnapshot; const or not) in order:
/// std::vector<double>& for double fields, std::vector<int64_t>& for controller_next_update,
/// so `f` is a generic lambda. e.g. copying: ForEachStateField([](const StateFieldInfo&,
/// auto& dst, const auto& src) { dst = src; }, a, b).
template <typename F, typename... S>
void ForEachStateField(F&& f, S&... states) {
  for (const StateFieldInfo& info : kStateFields) {
    if (info.f64 != nullptr)
      f(info, (states.*info.f64)...);
    else
      f(info, (states.*info.i64)...);
  }
}

/// the sizes `state`'s vectors imply (each size / per; 0 for an empty vector).
StateDims StateDimsOf(const SimState& state);

/// "" when every vector of `state` has the size `dims` gives and every entry of a flag field
/// is 0 or 1; else the first problem: "<field> has N entries; expected M" or "eq_active[2] is
/// 0.5; expected 0 or 1".
std::string StateMismatch(const SimState& state, const StateDims& dims);

}  // namespace penumbra
