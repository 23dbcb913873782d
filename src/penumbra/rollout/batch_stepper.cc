#include "penumbra/rollout/batch_stepper.h"

#include <mujoco/mujoco.h>

#include <algorithm>
#include <string>

#include "penumbra/core/error.h"

namespace penumbra {

void BatchStepperConfig::Validate(int nu) const {
  if (num_copies < 1) {
    throw ConfigError("", 0, "num_copies",
                      "got " + std::to_string(num_copies) + "; expected an integer >= 1");
  }
  if (num_threads < 0) {
    throw ConfigError("", 0, "num_threads",
                      "got " + std::to_string(num_threads) + "; expected 0 (all cores) or >= 1");
  }
  if (substeps < 1) {
    throw ConfigError("", 0, "substeps",
                      "got " + std::to_string(substeps) + "; expected an integer >= 1");
  }
  if (actuation == BatchActuation::kJointPd) {
    const auto check = [&](const std::vector<double>& v, const char* name) {
      if (static_cast<int>(v.size()) != nu) {
        throw ConfigError("", 0, name,
                          "got " + std::to_string(v.size()) +
                              " gains; expected one per actuator (" + std::to_string(nu) + ")");
      }
      for (size_t i = 0; i < v.size(); ++i) {
        if (!(v[i] >= 0.0) || v[i] > 1e9) {
          throw ConfigError("", 0, std::string(name) + "[" + std::to_string(i) + "]",
                            "got " + std::to_string(v[i]) + "; expected a finite gain >= 0");
        }
      }
    };
    check(kp, "kp");
    check(kd, "kd");
  }
}

BatchStepper::BatchStepper(const std::string& mjcf_path, const BatchStepperConfig& config)
    : config_(config), pool_(config.num_threads) {
  char error[1024] = "";
  model_ = mj_loadXML(mjcf_path.c_str(), nullptr, error, sizeof(error));
  if (model_ == nullptr) {
    throw Error(mjcf_path + ": MuJoCo could not load the model: " + SanitizeForMessage(error));
  }
  try {
    config_.Validate(model_->nu);
    if (config_.actuation == BatchActuation::kJointPd) {
      for (int a = 0; a < model_->nu; ++a) {
        const int joint = model_->actuator_trnid[2 * a];
        const bool joint_trn = model_->actuator_trntype[a] == mjTRN_JOINT;
        if (!joint_trn || joint < 0 ||
            (model_->jnt_type[joint] != mjJNT_HINGE && model_->jnt_type[joint] != mjJNT_SLIDE)) {
          const char* name = mj_id2name(model_, mjOBJ_ACTUATOR, a);
          throw ConfigError(mjcf_path, 0,
                            std::string("actuator ") + (name ? name : "#" + std::to_string(a)),
                            "joint_pd actuation needs an actuator driving a hinge or slide joint");
        }
        act_qpos_adr_.push_back(model_->jnt_qposadr[joint]);
        act_dof_adr_.push_back(model_->jnt_dofadr[joint]);
      }
    }
    datas_.reserve(config_.num_copies);
    for (int i = 0; i < config_.num_copies; ++i) {
      mjData* d = mj_makeData(model_);
      if (d == nullptr)
        throw Error(mjcf_path + ": MuJoCo could not allocate data for copy " + std::to_string(i));
      datas_.push_back(d);
      mj_forward(model_, d);
    }
  } catch (...) {
    for (mjData* d : datas_) mj_deleteData(d);
    mj_deleteModel(model_);
    throw;
  }
}

BatchStepper::~BatchStepper() {
  for (mjData* d : datas_) mj_deleteData(d);
  mj_deleteModel(model_);
}

int BatchStepper::nq() const { return model_->nq; }
int BatchStepper::nv() const { return model_->nv; }
int BatchStepper::nu() const { return model_->nu; }
int BatchStepper::nsensordata() const { return model_->nsensordata; }
double BatchStepper::timestep() const { return model_->opt.timestep; }

const mjData_* BatchStepper::data(int index) const {
  if (index < 0 || index >= num_copies()) {
    throw Error("BatchStepper: copy index " + std::to_string(index) + " out of range [0, " +
                std::to_string(num_copies()) + ")");
  }
  return datas_[index];
}

void BatchStepper::StepCopy(int64_t index, const double* input) {
  mjData* d = datas_[index];
  const int nu = model_->nu;
  const double* in = input + index * nu;
  if (config_.actuation == BatchActuation::kDirect) {
    std::copy(in, in + nu, d->ctrl);
    for (int s = 0; s < config_.substeps; ++s) mj_step(model_, d);
    return;
  }
  // joint PD every substep on the current state (legged_gym's compute_torques per sim step)
  for (int s = 0; s < config_.substeps; ++s) {
    for (int a = 0; a < nu; ++a) {
      const double q = d->qpos[act_qpos_adr_[a]];
      const double qd = d->qvel[act_dof_adr_[a]];
      d->ctrl[a] = config_.kp[a] * (in[a] - q) - config_.kd[a] * qd;
    }
    mj_step(model_, d);
  }
}

void BatchStepper::Step(const double* input) {
  pool_.ParallelFor(num_copies(), [&](int64_t i) { StepCopy(i, input); });
}

void BatchStepper::Reset(int index, const double* qpos, const double* qvel) {
  data(index);
  mjData* d = datas_[index];
  mj_resetData(model_, d);
  std::copy(qpos, qpos + model_->nq, d->qpos);
  std::copy(qvel, qvel + model_->nv, d->qvel);
  mj_forward(model_, d);
}

void BatchStepper::ReadState(double* qpos, double* qvel, double* ctrl, double* sensordata) const {
  const int nq = model_->nq, nv = model_->nv, nu = model_->nu, ns = model_->nsensordata;
  for (int i = 0; i < num_copies(); ++i) {
    const mjData* d = datas_[i];
    if (qpos) std::copy(d->qpos, d->qpos + nq, qpos + static_cast<size_t>(i) * nq);
    if (qvel) std::copy(d->qvel, d->qvel + nv, qvel + static_cast<size_t>(i) * nv);
    if (ctrl) std::copy(d->ctrl, d->ctrl + nu, ctrl + static_cast<size_t>(i) * nu);
    if (sensordata)
      std::copy(d->sensordata, d->sensordata + ns, sensordata + static_cast<size_t>(i) * ns);
  }
}

}  // namespace penumbra
