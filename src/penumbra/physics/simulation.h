#pragma once
// one MuJoCo model and its state, stepped at a fixed timestep, with the
// controllers that drive it. this is the only owner of mjModel/mjData; the rest
// of penumbra sees the world through scene() (static) and Snapshot() (per step).
//
// determinism: Step() is a pure function of the model, the state and the
// controllers' outputs (no wall clock, no randomness), so two simulations of the
// same model with the same controllers give bit-identical trajectories.
//
// failures: MuJoCo errors (e.g. stack overflow) and divergence (MuJoCo's bad
// qpos/qvel/qacc/ctrl warnings, or NaN/Inf in qpos/qvel/qacc) throw PhysicsError
// naming the sim time, the step and the body involved; MuJoCo resets its state on
// divergence, so after a PhysicsError the simulation refuses further steps.
// non-fatal MuJoCo warnings (contact or constraint buffer full, near-singular
// inertia) are collected for TakeWarnings().
//
// thread safety: one thread per Simulation; different Simulations may step on
// different threads. loading is serialised internally (MuJoCo's loader has global state).

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "penumbra/control/controller.h"
#include "penumbra/control/model_info.h"
#include "penumbra/physics/sensor_readout.h"
#include "penumbra/scene/scene_description.h"
#include "penumbra/scene/sim_time.h"
#include "penumbra/scene/world_snapshot.h"

namespace penumbra {

// PhysicsRateHz and SimTimeOfStep (the time of each step): scene/sim_time.h.

// SimState (what GetState / SetState carry) and its field table: scene/sim_state.h.

/// a MuJoCo simulation with pluggable controllers.
class Simulation {
 public:
  /// loads an MJCF (or URDF) file; `timestep_sec` overrides <option timestep> (the override
  /// wins, as physics.timestep_sec of a world file does).
  /// @throws ConfigError(mjcf_path, line, ...) with MuJoCo's message for a bad model, or
  ///         when the timestep used (override, else the model's) is outside
  ///         [kMinTimestepSec, kMaxTimestepSec] (scene/scene_limits.h: 0 would never advance,
  ///         a negative one runs backwards); PhysicsError if MuJoCo fails to set up the
  ///         model's data.
  static Simulation LoadFromFile(const std::string& mjcf_path,
                                 std::optional<double> timestep_sec = std::nullopt);
  /// loads MJCF text; assets (meshes, textures, includes) resolve relative to `asset_dir`
  /// ("" = the current directory). error messages name the model "<string>".
  /// @throws as LoadFromFile.
  static Simulation LoadFromString(const std::string& mjcf_xml,
                                   std::optional<double> timestep_sec = std::nullopt,
                                   const std::string& asset_dir = "");

  Simulation(Simulation&&) noexcept;
  Simulation& operator=(Simulation&&) noexcept;
  ~Simulation();

  /// takes ownership of `controller` and initialises it against the model.
  /// @throws ConfigError from Controller::Initialize (lists every missing name).
  void AddController(std::unique_ptr<Controller> controller);

  /// drives the mocap body `body_name` kinematically (NPC agents, effects/agent_path.h):
  /// its mocap_pos / mocap_quat are set to X_WB(t) now and after every Step() for the new
  /// time, so the body's pose always matches the time, for the controllers, the contacts of
  /// the next step and Snapshot(). t is the episode's time, the controllers' clock
  /// (SimTimeOfStep(step_count() - controller_episode_start(), timestep()): time() until the
  /// first ResetControllers, then from 0 again at each), so an agent's path restarts with the
  /// episode. coupling is one-way:
  /// other bodies collide with it and are pushed; it ignores contact. X_WB must be a pure
  /// function of t (determinism). drivers apply in the order they were added.
  /// @throws ConfigError("", 0, "mocap driver", ...) naming the body if no body has that
  ///         name or it is not a mocap body (MJCF mocap="true").
  void AddMocapDriver(const std::string& body_name, std::function<Pose(double time_sec)> X_WB);

  /// advances one timestep: controllers that are due (on sim time, see
  /// Controller::rate_hz) read the current state and write ctrl, then MuJoCo integrates.
  /// no allocation in steady state.
  /// @throws PhysicsError on a MuJoCo error, divergence, or a controller writing a
  ///         non-finite ctrl; message: "<model>: t = <time> s (step <n>): ... body '<name>' ...".
  void Step();

  /// runs the controllers due at the current step now (MuJoCo's position and velocity stages,
  /// then each due controller writes ctrl), as the next Step() would, so that a snapshot of
  /// this instant already holds the ctrl the step from it applies: its accelerations and
  /// acceleration sensors (an IMU's accelerometer) are those of the applied forces, not of
  /// the ctrl before the first control update (a standing robot with ctrl 0 falls freely and
  /// its IMU reads 0 instead of gravity). the next Step() does not run them again at this
  /// step, so the trajectory is the same bit for bit. no-op when no controller is due or they
  /// already ran at this step (physics/physics_source.h calls it before the first snapshot of
  /// a run; later snapshots hold the ctrl of the last update, so an update that falls on a
  /// snapshot's step shows in the next one).
  /// @throws PhysicsError as Step() does for a controller writing a non-finite ctrl.
  void RunDueControllers();

  /// starts a new controller episode at the current step: every controller's Reset() (back
  /// to its state right after Initialize), and the controllers' clock restarts at 0, so
  /// controllers see ControlInput::time_sec() = SimTimeOfStep(step_count() - episode start,
  /// timestep()) and update on that clock (update k at the first step whose clock time is at
  /// least k / rate_hz; every controller is due at the next step). with the same physics state
  /// and the same commands, the steps that follow are bit-identical to those after any other
  /// call at any other step. sim time() and step_count() go on. the `reset` command calls it
  /// after restoring the physics state. from the thread that steps the simulation.
  void ResetControllers();
  /// the step of the last ResetControllers (0 when there was none): the controllers' clock
  /// is the sim time since it.
  int64_t controller_episode_start() const;

  /// the current state (SimState: physics, step count, controller schedule).
  SimState GetState() const;
  /// as GetState(), into `out`, reusing its vectors' storage.
  void GetState(SimState* out) const;
  /// restores a state taken with GetState from a Simulation of the same model with the same
  /// number of controllers: the following steps are bit-identical to those that followed
  /// GetState (with stateless controllers and the same controller episode start; see SimState).
  /// a state before the episode start (ResetControllers) sets the episode start back to 0. also
  /// clears a PhysicsError, so a simulation can be restarted from a state before it failed.
  /// @throws Error naming the first field whose size does not match this model or a flag
  ///         (eq_active) that is not 0 or 1 (StateMismatch), or when time_sec is not
  ///         SimTimeOfStep(step, timestep()); the state is unchanged then.
  void SetState(const SimState& state);

  /// poses the mocap bodies among `mocap_ids` (mocap ids, see MocapBodyNames) that have a
  /// driver (AddMocapDriver) for the current episode time, as Step() does for all of them; ids
  /// without a driver are left alone. a kinematic replay uses it after SetState of a recorded
  /// state to move the driven bodies the recording does not hold.
  /// @throws Error for an id outside [0, number of mocap bodies).
  void ApplyMocapDrivers(std::span<const int> mocap_ids);

  /// sets the state of one composed model from one of its keyframes: for the MJCF key named
  /// `key` (e.g. "go1/home"), the qpos and qvel of every joint, the ctrl (and act) of every
  /// actuator and the mocap pose of every mocap body whose name starts with `prefix` (e.g.
  /// "go1/") are copied from the key; an unnamed element counts by what it belongs to (a joint
  /// by its body, a body by its nearest named ancestor, an actuator by its transmission's
  /// joint, site, body or tendon); everything else is left as it is. then the derived
  /// quantities are recomputed (mj_forward). call before the first Step(), e.g. for the world
  /// file's `initial_keyframe`.
  /// @throws ConfigError("", 0, `error_key`, ...) when the model has no key `key`, naming the
  ///         keys that `prefix` has.
  void ApplyKeyframe(const std::string& key, const std::string& prefix,
                     const std::string& error_key);

  /// simulation time (s) and the number of steps completed since loading. time() is
  /// SimTimeOfStep(step_count(), timestep()) (MuJoCo's accumulated time is overwritten after
  /// each step), also for controllers and snapshots. after a PhysicsError both stay at the
  /// last completed step: the sim time reached.
  double time() const;
  int64_t step_count() const;
  /// the physics timestep (s).
  double timestep() const;

  /// what a snapshot computes. both work on a scratch copy of the state, so taking snapshots
  /// never changes the trajectory, and both give bit-identical poses.
  enum class SnapshotContent {
    /// time, X_WB of every body, MJCF camera poses, light positions/directions, the state
    /// (SnapshotState: qpos, qvel, act, ctrl, ...):
    /// mj_kinematics, mj_comPos and mj_camlight for the current qpos and mocap poses (what
    /// cameras and effects read; a small part of a step). sensordata, V_WB, contacts,
    /// qfrc_actuator and tracking_error are left empty.
    kPoses,
    /// kPoses plus sensordata, V_WB, contacts, qfrc_actuator and the controllers' tracking
    /// errors: the whole mj_forward for the current state (collision, constraint forces,
    /// every sensor stage; about the cost of a step).
    kFull,
  };

  /// copies the current state into `out`'s SimState part (GetState(out)) and its
  /// episode_start_step, reusing its storage; the other fields are left as they are.
  /// Snapshot() does this too.
  void SnapshotState(WorldSnapshot* out) const;

  /// the world at the current time (see SnapshotContent).
  WorldSnapshot Snapshot(SnapshotContent content = SnapshotContent::kFull) const;
  /// as Snapshot(), reusing `out`'s storage.
  void Snapshot(WorldSnapshot* out, SnapshotContent content = SnapshotContent::kFull) const;

  /// the model's MuJoCo sensors (name, type, dimension, unit, object), by sensor id; their
  /// values are WorldSnapshot::sensordata (physics/sensor_readout.h).
  const std::vector<SensorDescription>& sensor_info() const;

  /// the static scene, extracted once at load (physics/scene_extractor.h).
  const SceneDescription& scene() const;
  /// names, sizes and index maps for controllers.
  const ModelInfo& model_info() const;

  /// non-fatal warnings since the last call (loader warnings first), each with sim time,
  /// step and body where MuJoCo names one. clears the list.
  std::vector<std::string> TakeWarnings();

  /// (nq) / (nv) current joint positions and velocities.
  std::span<const double> qpos() const;
  std::span<const double> qvel() const;
  /// (nu) MuJoCo ctrl vector; controllers write it, tools and tests may too.
  std::span<double> ctrl();

  /// the names of the mocap bodies by mocap id (the order of SimState::mocap_pos / mocap_quat).
  std::vector<std::string> MocapBodyNames() const;
  /// true when mocap body `mocap_id` has a driver (AddMocapDriver), which poses it every step.
  /// @throws Error for an id outside [0, number of mocap bodies).
  bool MocapDriven(int mocap_id) const;
  /// sets the pose X_WB of mocap body `mocap_id` (position m, world frame; the rotation is
  /// stored as a unit quaternion); it holds until set again. a driven body (MocapDriven) is
  /// moved back by its driver at the next step. between steps, on the stepping thread.
  /// @throws Error for a bad id or a non-finite pose.
  void SetMocapPose(int mocap_id, const Pose& X_WB);

  /// the file the model came from ("<string>" for LoadFromString).
  const std::string& source() const;
  /// controllers added so far, in order.
  int num_controllers() const;
  const Controller& controller(int i) const;
  /// controller `i` for commands (e.g. TrotGait::SetCommand); use it only from the thread that
  /// steps the simulation, between steps. @throws std::out_of_range for a bad index.
  Controller& mutable_controller(int i);

 private:
  struct Impl;
  explicit Simulation(std::unique_ptr<Impl> impl);
  static std::unique_ptr<Impl> LoadImpl(const std::string& loader_path, const std::string* contents,
                                        const std::string& source,
                                        std::optional<double> timestep_sec);
  std::unique_ptr<Impl> impl_;
};

}  // namespace penumbra
