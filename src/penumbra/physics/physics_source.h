#pragma once
// live physics as a pipeline source (pipeline/source.h): a Simulation stepped one timestep per
// Advance, optionally paced to wall-clock time, with snapshots of the requested content.

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>

#include "penumbra/physics/simulation.h"
#include "penumbra/pipeline/source.h"

namespace penumbra {

/// a new snapshot of `sim`'s current state with `content` (pipeline/source.h): kState (and
/// kNone) the state only (Simulation::SnapshotState: time, step, the SimState vectors);
/// kPoses / kFull Simulation::Snapshot's kPoses / kFull. for sources that hold a Simulation
/// (live physics, a replayed log set into one).
std::shared_ptr<WorldSnapshot> TakeSnapshot(const Simulation& sim, SnapshotContent content);

/// settings of a PhysicsSource.
struct PhysicsSourceOptions {
  /// pace the steps to wall-clock time: step n is not taken before n * timestep seconds of
  /// wall time have passed since the first Advance (default: as fast as possible). the
  /// trajectory does not depend on it.
  bool realtime = false;
  /// called by Advance before each Simulation::Step with the simulation about to step (e.g.
  /// to set its ctrl: replay/resimulate.h applies the logged ctrl); returning false ends the
  /// source there (Advance returns false without stepping). empty = none.
  /// @throws anything: Advance throws it, and the loop ends with that error.
  std::function<bool(Simulation& sim)> before_step;
};

/// a Simulation as a Source. not thread-safe (one loop thread; the simulation must not be used
/// elsewhere while the loop runs).
class PhysicsSource : public Source {
 public:
  /// `sim` must outlive the source.
  explicit PhysicsSource(Simulation* sim, PhysicsSourceOptions options = {});

  /// the step and time of the last step completed (after a PhysicsError: the step before it).
  int64_t step() const override { return step_; }
  double time_sec() const override { return time_sec_; }
  /// kState: the state only (Simulation::SnapshotState: time, step, qpos, qvel, act, ctrl,
  /// ...); kPoses / kFull: Simulation::Snapshot's kPoses / kFull (which include the state).
  /// before the first Advance, the controllers due at the start run first
  /// (Simulation::RunDueControllers): the first snapshot holds the ctrl of the first step and
  /// its sensors (an IMU) see those forces, not a robot with ctrl 0.
  std::shared_ptr<const WorldSnapshot> Snapshot(SnapshotContent content) override;
  /// one Simulation::Step (after the realtime wait and PhysicsSourceOptions::before_step);
  /// logs the simulation's warnings. true, or false when before_step returned false.
  /// @throws PhysicsError when the simulation diverges; what before_step throws.
  bool Advance() override;

  /// wall time spent inside Simulation::Step so far, s.
  double busy_sec() const { return busy_sec_; }

 private:
  using Clock = std::chrono::steady_clock;
  Simulation* sim_;
  PhysicsSourceOptions options_;
  int64_t step_ = 0;
  double time_sec_ = 0;
  std::optional<Clock::time_point> wall0_;
  double busy_sec_ = 0;
  bool advanced_ = false;  // Advance was called: the controllers have run at least once
};

}  // namespace penumbra
