#pragma once
// N independent copies of one MuJoCo model stepped together on a thread pool: the batched
// rollout behind reinforcement-learning training (train/) and the Python vector environment
// (python/penumbra_rollout). every copy owns its mjData; copies share the read-only mjModel.
// a copy's trajectory depends only on its own state and inputs, so N copies stepped together
// are bit-identical to each copy stepped alone, for any thread count.

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
  /// copies of the model, >= 1.
  int num_copies = 1;
  /// threads stepping the copies, including the caller; 0 = hardware concurrency.
  int num_threads = 0;
  /// mj_step calls per Step (the policy's decimation), >= 1.
  int substeps = 1;
  BatchActuation actuation = BatchActuation::kDirect;
  /// kJointPd gains, one per actuator (N m/rad, N m s/rad for hinge joints); ignored for kDirect.
  std::vector<double> kp, kd;

  /// throws ConfigError naming the field when a value is out of range (nu: the model's
  /// actuator count, to check the gain vectors against).
  void Validate(int nu) const;
};

/// N copies of one MJCF model. not thread-safe: one call at a time.
class BatchStepper {
 public:
  /// loads `mjcf_path` once and makes config.num_copies copies of its initial state (qpos0).
  /// throws Error naming the file and MuJoCo's message when the model does not load, and
  /// ConfigError for a bad config; in kJointPd mode every actuator must drive a hinge or
  /// slide joint (else ConfigError naming the actuator).
  BatchStepper(const std::string& mjcf_path, const BatchStepperConfig& config);
  ~BatchStepper();
  BatchStepper(const BatchStepper&) = delete;
  BatchStepper& operator=(const BatchStepper&) = delete;

  /// advances every copy by `substeps` mj_step calls. `input` holds num_copies x nu values,
  /// row-major (copy i's values at input[i * nu]), read as BatchActuation says.
  void Step(const double* input);

  /// sets copy `index`'s state: qpos (nq values), qvel (nv values), time 0, act and ctrl 0,
  /// warm-start accelerations cleared, then mj_forward. throws Error for an index out of range.
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
  int num_threads() const { return pool_.num_threads(); }
  int substeps() const { return config_.substeps; }
  int nq() const;
  int nv() const;
  int nu() const;
  int nsensordata() const;
  /// the model's physics timestep (s).
  double timestep() const;

 private:
  void StepCopy(int64_t index, const double* input);

  BatchStepperConfig config_;
  mjModel_* model_ = nullptr;
  std::vector<mjData_*> datas_;
  // kJointPd: qpos and dof address of the joint each actuator drives
  std::vector<int> act_qpos_adr_, act_dof_adr_;
  ThreadPool pool_;
};

}  // namespace penumbra
