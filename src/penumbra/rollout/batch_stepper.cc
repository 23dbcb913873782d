#include "penumbra/rollout/batch_stepper.h"

#include <mujoco/mujoco.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <memory>
#include <mutex>
#include <string>
#include <system_error>

#include "penumbra/core/error.h"
#include "penumbra/rollout/rollout_args.h"

namespace penumbra {
namespace {

// MuJoCo's default error handler prints and calls exit(1); its default warning handler prints
// and appends to MUJOCO_LOG.TXT in the working folder. these replace them when the process has
// none of its own (physics/ installs equivalent ones): errors throw, warnings are dropped
// (MuJoCo counts them in mjData::warning).
void ThrowingErrorHandler(const char* msg) {
  throw PhysicsError(std::string("MuJoCo error: ") + (msg ? msg : "unknown error"));
}

void SilentWarningHandler(const char*) {}

void InstallHandlers() {
  static std::once_flag once;
  std::call_once(once, [] {
    if (mju_user_error == nullptr) mju_user_error = ThrowingErrorHandler;
    if (mju_user_warning == nullptr) mju_user_warning = SilentWarningHandler;
  });
}

// MuJoCo's XML loader keeps global state: one load at a time
std::mutex& LoaderMutex() {
  static std::mutex mu;
  return mu;
}

// loads `xml` as the file `name` through a MuJoCo VFS (assets resolve beside `name`)
mjModel* LoadModel(const std::string& name, const std::string& xml) {
  if (xml.size() > kMaxRolloutModelFileBytes) {
    throw ConfigError(name, 0, "model_path",
                      "model is " + std::to_string(xml.size()) + " bytes; expected at most " +
                          std::to_string(kMaxRolloutModelFileBytes) + " bytes");
  }
  std::lock_guard<std::mutex> lock(LoaderMutex());
  auto vfs = std::make_unique<mjVFS>();
  mj_defaultVFS(vfs.get());
  const std::string file = std::filesystem::path(name).filename().string();
  if (file.empty() ||
      mj_addBufferVFS(vfs.get(), file.c_str(), xml.data(), static_cast<int>(xml.size())) != 0) {
    mj_deleteVFS(vfs.get());
    throw ConfigError(name, 0, "model_path",
                      "cannot hand the model to MuJoCo; expected an MJCF file name");
  }
  char error[1024] = "";
  mjModel* m = nullptr;
  try {
    m = mj_loadXML(name.c_str(), vfs.get(), error, sizeof(error));
  } catch (const std::exception& e) {
    mj_deleteVFS(vfs.get());
    throw ConfigError(name, 0, "model_path",
                      std::string("MuJoCo could not load the model: ") + e.what());
  }
  mj_deleteVFS(vfs.get());
  if (m == nullptr) {
    throw ConfigError(name, 0, "model_path",
                      std::string("MuJoCo could not load the model: ") + error);
  }
  return m;
}

}  // namespace

void BatchStepperConfig::Validate(int nu) const {
  ValidateRolloutCounts(num_copies, num_threads, substeps);
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
                            "got " + std::to_string(v[i]) + "; expected a finite gain in [0, 1e9]");
        }
      }
    };
    check(kp, "kp");
    check(kd, "kd");
  }
}

BatchStepper::BatchStepper(const std::string& mjcf_path, const BatchStepperConfig& config)
    : config_(config) {
  // counts first: nothing is opened, allocated or started for a bad config
  ValidateRolloutCounts(config_.num_copies, config_.num_threads, config_.substeps);
  Init(mjcf_path, ReadRolloutModelFile(mjcf_path));
}

BatchStepper::BatchStepper(const MjcfText& mjcf, const BatchStepperConfig& config)
    : config_(config) {
  ValidateRolloutCounts(config_.num_copies, config_.num_threads, config_.substeps);
  Init(mjcf.name, mjcf.xml);
}

void BatchStepper::Init(const std::string& mjcf_path, const std::string& xml) {
  InstallHandlers();
  model_ = LoadModel(mjcf_path, xml);
  try {
    config_.Validate(model_->nu);
    if (config_.actuation == BatchActuation::kJointPd) {
      // MuJoCo 4 multi-input actuators (<orientation>) make nu, the controls, exceed the actuators
      if (model_->nactuator != model_->nu)
        throw ConfigError(mjcf_path, 0, "actuation",
                          "joint_pd actuation needs one control per actuator; the model has " +
                              std::to_string(model_->nactuator) + " actuators with " +
                              std::to_string(model_->nu) + " controls");
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
    // the first copy's size bounds the others before they are allocated
    CheckRolloutMemory(1, sizeof(mjData) + static_cast<size_t>(model_->narena));
    datas_.reserve(config_.num_copies);
    for (int i = 0; i < config_.num_copies; ++i) {
      mjData* d = mj_makeData(model_);
      if (d == nullptr)
        throw Error(mjcf_path + ": MuJoCo could not allocate data for copy " + std::to_string(i));
      datas_.push_back(d);
      if (i == 0) {
        copy_bytes_ =
            sizeof(mjData) + static_cast<size_t>(d->nbuffer) + static_cast<size_t>(d->narena);
        CheckRolloutMemory(config_.num_copies, copy_bytes_);
      }
      mj_forward(model_, d);
    }
    try {
      pool_ = std::make_unique<ThreadPool>(config_.num_threads);
    } catch (const std::system_error& e) {
      throw Error("num_threads " + std::to_string(config_.num_threads) +
                  ": could not start the stepper's threads (" + e.what() +
                  "); the threads already started were stopped; expected fewer threads");
    }
  } catch (...) {
    for (mjData* d : datas_) mj_deleteData(d);
    datas_.clear();
    mj_deleteModel(model_);
    model_ = nullptr;
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
  try {
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
  } catch (const std::exception& e) {
    // an error thrown out of mj_step leaves MuJoCo's stack marked: nothing lives on it between
    // top-level calls
    d->pstack = 0;
    throw PhysicsError("copy " + std::to_string(index) + ": " + e.what() +
                       "; expected a copy that MuJoCo can step (reset it)");
  }
}

void BatchStepper::Step(const double* input) {
  CheckFiniteValues(input, static_cast<size_t>(num_copies()) * model_->nu, model_->nu, "input");
  pool_->ParallelFor(num_copies(), [&](int64_t i) { StepCopy(i, input); });
}

void BatchStepper::Reset(int index, const double* qpos, const double* qvel) {
  data(index);
  CheckFiniteValues(qpos, model_->nq, 1, "qpos");
  CheckFiniteValues(qvel, model_->nv, 1, "qvel");
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
