#pragma once
// a source of world snapshots for the SimLoop (pipeline/sim_loop.h): something that stands at
// one step of a run, can hand out the world at that step as an immutable WorldSnapshot and move
// on to the next step. live physics is one (physics/physics_source.h); a recorded run read
// back from a log is another (it has every snapshot already and only walks through them).

#include <cstdint>
#include <memory>

#include "penumbra/scene/world_snapshot.h"

namespace penumbra {

/// how much of a WorldSnapshot a consumer reads; ordered from least to most (a richer content
/// holds everything of a poorer one).
enum class SnapshotContent {
  kNone = 0,  ///< no snapshot at this step
  /// the snapshot's SimState part (scene/sim_state.h): time_sec, step, qpos, qvel and, from
  /// live physics, every other field of the state table (trajectory rows, recorders)
  kState = 1,
  kPoses = 2,  ///< kState plus X_WB, X_W_mjcam, light poses (cameras, effects)
  kFull = 3,   ///< kPoses plus sensordata, V_WB, contacts, qfrc_actuator, tracking_error
};

/// the richer of two contents.
inline SnapshotContent Richer(SnapshotContent a, SnapshotContent b) {
  return static_cast<int>(a) >= static_cast<int>(b) ? a : b;
}

/// a run's stream of world states, one position (step) at a time. used from one thread at a
/// time (the SimLoop's). snapshots it returns are never changed afterwards, so they may be
/// shared with other threads.
class Source {
 public:
  virtual ~Source() = default;

  /// steps taken since the start of the run at the current position (0 at the start).
  virtual int64_t step() const = 0;
  /// simulation time at the current position, s.
  virtual double time_sec() const = 0;

  /// the world at the current position with at least `content` (not kNone) filled in; fields
  /// beyond it may be empty. a source that holds richer snapshots (a log) may return them.
  /// @throws Error if the source cannot produce that content (e.g. a log recorded without it).
  virtual std::shared_ptr<const WorldSnapshot> Snapshot(SnapshotContent content) = 0;

  /// moves to the next step. returns false, staying where it is, when the source has no
  /// further step (a log ended); live physics always advances.
  /// @throws PhysicsError (core/error.h) when the simulation diverges; Error for a source that
  ///         cannot be read.
  virtual bool Advance() = 0;
};

}  // namespace penumbra
