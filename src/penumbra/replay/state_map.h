#pragma once
// how the state recorded in a run log (runlog/run_log_format.h) maps onto the state of the model
// a replay loads, BY NAME: the replay model is composed again from the recorded world and may
// differ from the recorded one in what a replay is allowed to change (an adversity preset adds
// NPC agents as mocap bodies; a world override adds or removes agents), so ids and addresses
// can move. the rules:
//
//   joints         every joint of the log must be in the replay model with the same type and
//                  widths, and every joint of the replay model must be in the log: qpos and
//                  every field of size nv (scene/sim_state.h) are copied joint by joint. a missing
//                  joint or a changed width is an error naming it (robots and models cannot change
//                  in a replay).
//   actuators      the same, for ctrl and act: with the same actuators in the same order and
//                  the same nu and na, both are copied whole (MuJoCo 4 puts stateful actuators
//                  anywhere, with one or more activations each); otherwise one ctrl per
//                  actuator and act[i] for actuator nu - na + i (MuJoCo 2.2.2's order, the
//                  stateful actuators last).
//   mocap bodies   those of the log are copied into the replay model's mocap body of the same
//                  name (recorded agents follow the log); a logged mocap body the replay model
//                  lacks is dropped (e.g. a replay under --adversity none of a run recorded
//                  under a preset); the replay model's mocap bodies the log lacks are listed
//                  by unlogged_mocap() (they keep following their own drivers, as functions of
//                  time: an adversity preset's NPCs added by the replay).
//   bodies         xfrc_applied is copied per body name; bodies of one side only keep zero.
//   userdata       copied whole; a different nuserdata is an error.
//   history, eq_active, plugin_state, plastic
//                  copied whole; a different nhistory, neq, npluginstate or nplastic is an
//                  error, but for a log that holds none (a format 1 log records none of them,
//                  docs/run-log.md "Versions"): the replay model keeps its own values.
// unnamed objects (MJCF without a name) are matched by their order among the unnamed objects of
// the same kind. the controllers' schedule (controller_next_update) is not mapped: a kinematic
// replay runs no controllers.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "penumbra/physics/simulation.h"
#include "penumbra/runlog/run_log_format.h"

namespace penumbra {

/// the per-name copy plan from a log's state layout to a replay model's.
class StateMap {
 public:
  /// plans the copy from `log` (the header's layout) to `model` (the replay model's layout,
  /// live/run_log_header.h RunLogLayoutOf). `log_name` names the log in errors.
  /// @throws ConfigError(log_name, 0, "", ...) naming the first joint or actuator of the log
  ///         that the replay model lacks or holds with another type or width, the first joint
  ///         or actuator of the replay model that the log lacks, a different nuserdata, or
  ///         a different nhistory, neq, npluginstate or nplastic where the log holds some.
  StateMap(const RunLogLayout& log, const RunLogLayout& model, const std::string& log_name);

  /// writes the values of `record` (sizes of the log's layout) into `state` (sizes of the
  /// model's layout), entry by entry as planned; entries the log has no values for (unlogged
  /// mocap bodies, bodies new to the model) are left as they are. step_count and time_sec are
  /// copied; controller_next_update is left as it is.
  /// @throws Error if a vector of `record` or `state` does not have its layout's size.
  void Apply(const StepRecord& record, SimState* state) const;

  /// mocap ids of the replay model that the log does not hold, increasing.
  const std::vector<int>& unlogged_mocap() const { return unlogged_mocap_; }
  /// names of the logged mocap bodies the replay model lacks (dropped), in log order.
  const std::vector<std::string>& dropped_mocap() const { return dropped_mocap_; }
  /// true when both layouts are the same (every vector the log holds is copied whole, index
  /// for index).
  bool identity() const { return identity_; }

 private:
  // a run of `length` entries copied from src[src_adr] to dst[dst_adr]
  struct Span {
    int src = 0, dst = 0, length = 0;
  };
  static void AddSpan(std::vector<Span>* spans, int src, int dst, int length);

  RunLogLayout log_, model_;
  std::vector<Span>& Spans(StateDim dim) { return spans_[static_cast<size_t>(dim)]; }
  // the copy plan per state dimension, in its units (a field of `per` entries per unit copies
  // per * length entries); the controllers' dimension stays empty (not mapped)
  std::array<std::vector<Span>, kNumStateDims> spans_;
  std::vector<int> unlogged_mocap_;
  std::vector<std::string> dropped_mocap_;
  bool identity_ = false;
};

/// index in `model` of each entry of `log`, or -1: named entries match by name, unnamed ones
/// ("") by their order among the unnamed entries. names are unique per kind (MuJoCo).
std::vector<int> MatchNames(const std::vector<std::string>& log,
                            const std::vector<std::string>& model);

}  // namespace penumbra
