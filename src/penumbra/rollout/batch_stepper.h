#pragma once
// N independent copies of one MuJoCo model stepped together on a thread pool: the batched
// rollout behind reinforcement-learning training (train/) and the Python vector environment
// (python/penumbra_rollout). every copy owns its mjData; copies share the read-only mjModel.
// a copy's trajectory depends only on its own state and inputs, so N copies stepped together
// are bit-identical to each copy stepped alone, for any thread count.
// every count, size and input is bounded before anything is allocated or started
// (rollout/rollout_args.h); MuJoCo errors become exceptions (never MuJoCo's exit()).

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "penumbra/core/thread_pool.h"

struct mjModel_;
struct mjData_;

namespace penumbra {

/// how BatchStepper::Step reads its per-copy input vector.
enum class BatchActuation {
  /// the input is mjData::ctrl (one value per actuator), held for every substep.
  kDirect,
  /// the input is one joint position target per actuator (radians or metres of the joint the
  /// actuator drives); every substep the actuator's ctrl is the PD law
  /// ctrl = kp (target - q) - kd qdot of that joint (legged_gym's "P" control type: torque
  /// motors as position servos), clamped by MuJoCo to the actuator's ctrlrange.
  kJointPd,
};

/// settings of a BatchStepper.
struct BatchStepperConfig {
  /// copies of the model, in [1, kMaxRolloutCopies], and their memory within
  /// RolloutMemoryCap() (rollout_args.h).
  int num_copies = 1;
  /// threads stepping the copies, including the caller; 0 = hardware concurrency; at most
  /// MaxRolloutThreads() (4 x the hardware threads).
  int num_threads = 0;
  /// mj_step calls per Step (the policy's decimation), in [1, kMaxRolloutSubsteps].
  int substeps = 1;
  BatchActuation actuation = BatchActuation::kDirect;
  /// kJointPd gains, one per actuator (N m/rad, N m s/rad for hinge joints); ignored for kDirect.
  std::vector<double> kp, kd;

  /// throws ConfigError naming the field and the bound when a value is out of range (nu: the
  /// model's actuator count, to check the gain vectors against; gains finite, in [0, 1e9]).
  void Validate(int nu) const;
};

/// an MJCF model given as text instead of a file (a test's or a fuzzer's built-in model).
struct MjcfText {
  /// the name messages give the model.
  std::string name;
  /// the MJCF document (it may not name asset files).
  std::string xml;
};

/// N copies of one MJCF model. not thread-safe: one call at a time.
class BatchStepper {
 public:
  /// loads `mjcf_path` once and makes config.num_copies copies of its initial state (qpos0).
  /// the config is checked before the file is opened and before any thread starts; the file
  /// must be a regular file (ReadRolloutModelFile: never blocks on a FIFO); the copies' memory
  /// (measured on the first copy) is checked against RolloutMemoryCap() before the others are
  /// made. installs MuJoCo error handlers that throw (once per process, unless the process
  /// already has its own).
  /// @throws ConfigError naming the field and its bound for a bad config, the file for one
  ///         that is not a readable regular file or does not load (MuJoCo's message), the
  ///         actuator in kJointPd mode for one that does not drive a hinge or slide joint;
  ///         Error when a thread cannot be started (the threads already started are joined)
  ///         or MuJoCo reports an error (e.g. out of memory).
  BatchStepper(const std::string& mjcf_path, const BatchStepperConfig& config);
  /// the same for a model given as text (read as the file `mjcf.name` would be, with no
  /// asset files).
  BatchStepper(const MjcfText& mjcf, const BatchStepperConfig& config);
  ~BatchStepper();
  BatchStepper(const BatchStepper&) = delete;
  BatchStepper& operator=(const BatchStepper&) = delete;

  /// advances every copy by `substeps` mj_step calls. `input` holds num_copies x nu values,
  /// row-major (copy i's values at input[i * nu]), read as BatchActuation says.
  /// @throws ConfigError("", 0, "input[i, j]", ...) for a value that is not finite (checked
  ///         before any copy moves); PhysicsError naming the copy when MuJoCo reports an error
  ///         (that copy should then be Reset).
  void Step(const double* input);

  /// sets copy `index`'s state: qpos (nq values), qvel (nv values), time 0, act and ctrl 0,
  /// warm-start accelerations cleared, then mj_forward.
  /// @throws Error for an index out of range, ConfigError("", 0, "qpos[i]" | "qvel[i]", ...)
  ///         for a value that is not finite (the copy is left as it was).
  void Reset(int index, const double* qpos, const double* qvel);

  /// copies the state of every copy into row-major arrays: qpos num_copies x nq, qvel
  /// num_copies x nv, ctrl num_copies x nu (the last substep's actuator inputs), sensordata
  /// num_copies x nsensordata. any pointer may be null to skip that array.
  void ReadState(double* qpos, double* qvel, double* ctrl, double* sensordata) const;

  /// the shared model (read-only).
  const mjModel_* model() const { return model_; }
  /// copy `index`'s data; throws Error for an index out of range.
  const mjData_* data(int index) const;
  int num_copies() const { return static_cast<int>(datas_.size()); }
  int num_threads() const { return pool_->num_threads(); }
  int substeps() const { return config_.substeps; }
  int nq() const;
  int nv() const;
  int nu() const;
  int nsensordata() const;
  /// the model's physics timestep (s).
  double timestep() const;
  /// memory one copy takes (bytes: mjData, its buffer and its stack), the size the copies'
  /// memory is checked with against RolloutMemoryCap().
  size_t copy_bytes() const { return copy_bytes_; }

 private:
  void Init(const std::string& name, const std::string& xml);
  void StepCopy(int64_t index, const double* input);

  BatchStepperConfig config_;
  mjModel_* model_ = nullptr;
  std::vector<mjData_*> datas_;
  size_t copy_bytes_ = 0;
  // kJointPd: qpos and dof address of the joint each actuator drives
  std::vector<int> act_qpos_adr_, act_dof_adr_;
  std::unique_ptr<ThreadPool> pool_;
};

}  // namespace penumbra
