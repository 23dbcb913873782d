#pragma once
// a run log (runlog/run_log_reader.h) as a pipeline source (pipeline/source.h): a kinematic
// replay. each step's snapshot is computed from the logged state with no dynamics: the logged
// state is mapped by name onto the replay model (replay/state_map.h), set into its Simulation
// (SetState), the driven mocap bodies the log does not hold are posed for the step's time
// (their drivers: e.g. the NPCs of an adversity preset added by the replay), and the snapshot
// is taken as live physics takes it (Simulation::Snapshot: kPoses = kinematics, kFull = a whole
// mj_forward for sensors, velocities and contacts; both on a scratch copy). the simulation is
// never stepped, and the state is only set at steps a sink wants a snapshot of.
//
// with the model and state of the recorded run, a snapshot equals bit for bit the one live
// physics took at that step (the same mjData inputs into the same MuJoCo functions), so the
// sinks write the same files.
//
// the log's `reset` commands ("command" events, docs/run-log.md) start an episode in the replay
// model at their step as they did in the run (Simulation::ResetControllers after the state of
// that step is set), so that the sensors and cameras, which restart their schedules and noise
// streams with each episode (sinks/sensor_sink.h, sinks/camera_sink.h), sample as in the run.
// a replay that starts (LogSourceOptions::first_step) after a reset samples as from episode 0.

#include <cstdint>
#include <memory>
#include <set>
#include <string>

#include "penumbra/physics/simulation.h"
#include "penumbra/pipeline/source.h"
#include "penumbra/replay/state_map.h"
#include "penumbra/runlog/run_log_reader.h"

namespace penumbra {

/// refuses to replay a log with a model whose physics timestep differs from the timestep the
/// log's header records: the one check that kinematic replays (LogSource) and
/// `replay --resimulate` (ResimulateLog) both make, after the reader has checked the header's
/// own values (runlog_codec::CheckHeader).
/// @throws ConfigError naming `log_path`, both timesteps (s) and what was expected.
void CheckLoggedTimestep(const RunLogHeader& header, const Simulation& sim,
                         const std::string& log_path);

/// settings of a LogSource.
struct LogSourceOptions {
  /// the source starts at the first logged step >= first_step (0 = the log's first step).
  int64_t first_step = 0;
};

/// a kinematic replay of a run log. not thread-safe (one loop thread).
class LogSource : public Source {
 public:
  /// `reader` and `sim` must outlive the source; `sim` is the replay model loaded (e.g. a
  /// Session built without controllers), with its mocap drivers. reads the first step.
  /// @throws ConfigError naming the log when the replay model's timestep differs from the
  ///         log's, or from StateMap (a joint or actuator missing or changed); RunLogError
  ///         when the log has no step at or after first_step (naming its last step) or a
  ///         chunk cannot be read.
  LogSource(RunLogReader* reader, Simulation* sim, LogSourceOptions options = {});

  /// the logged step and time at the current position.
  int64_t step() const override { return current_.step; }
  double time_sec() const override { return current_.time_sec; }
  /// the world at the logged state. kState: time, step, qpos, qvel and the rest of the state
  /// (act, ctrl, ..., controller_next_update as logged); kPoses / kFull: Simulation::Snapshot
  /// of the replay model at that state, with the same state fields.
  /// @throws Error from Simulation::SetState; PhysicsError from Simulation::Snapshot.
  std::shared_ptr<const WorldSnapshot> Snapshot(SnapshotContent content) override;
  /// moves to the next logged step; false at the end of the log (of its usable chunks). at a
  /// step the log holds a `reset` command at, the replay model's episode starts there first.
  /// @throws RunLogError when a chunk cannot be read; Error from Simulation::SetState.
  bool Advance() override;

  /// the name mapping used.
  const StateMap& state_map() const { return map_; }

 private:
  RunLogReader* reader_;
  Simulation* sim_;
  StateMap map_;
  StepRecord current_, next_;
  SimState state_;                 // the replay model's state, reused
  int64_t applied_step_ = -1;      // step whose state is set in sim_
  std::set<int64_t> reset_steps_;  // steps of the log's `reset` commands
  // sets the logged state of the current step into sim_ (once per step)
  void ApplyCurrent();
};

}  // namespace penumbra
