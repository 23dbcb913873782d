#include "penumbra/physics/simulation.h"

#include <mujoco/mujoco.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <type_traits>

#include "penumbra/core/error.h"
#include "penumbra/core/number_text.h"
#include "penumbra/physics/mujoco_runtime.h"
#include "penumbra/physics/mujoco_state.h"
#include "penumbra/physics/scene_extractor.h"
#include "penumbra/physics/sensor_snapshot.h"
#include "penumbra/scene/scene_limits.h"

namespace penumbra {
namespace {

// stored messages per warning type; later ones are only counted
constexpr int kMaxMessagesPerWarning = 20;

// ControlInput over live MuJoCo data, valid during one control update
class MujocoControlInput final : public ControlInput {
 public:
  MujocoControlInput(const mjModel* m, mjData* d, const ModelInfo* info, std::vector<double>* jacp,
                     std::vector<double>* jacr, double time_sec)
      : m_(m), d_(d), info_(info), jacp_(jacp), jacr_(jacr), time_sec_(time_sec) {}

  double time_sec() const override { return time_sec_; }
  const ModelInfo& model() const override { return *info_; }
  std::span<const double> qpos() const override { return {d_->qpos, static_cast<size_t>(m_->nq)}; }
  std::span<const double> qvel() const override { return {d_->qvel, static_cast<size_t>(m_->nv)}; }
  std::span<const double> sensordata() const override {
    return {d_->sensordata, static_cast<size_t>(m_->nsensordata)};
  }
  std::span<const double> qfrc_bias() const override {
    return {d_->qfrc_bias, static_cast<size_t>(m_->nv)};
  }
  Pose X_WB(int body) const override {
    CheckBody(body, "X_WB");
    return PoseFromPosQuat(d_->xpos + 3 * body, d_->xquat + 4 * body);
  }
  Twist V_WB(int body) const override {
    CheckBody(body, "V_WB");
    mjtNum v[6];
    mj_objectVelocity(m_, d_, mjOBJ_XBODY, body, v, 0);
    Twist t;
    for (int i = 0; i < 6; ++i) t[i] = v[i];
    return t;
  }
  void Jacobian(int body, const Eigen::Vector3d& p_W,
                Eigen::Matrix<double, 6, Eigen::Dynamic>* J) const override {
    CheckBody(body, "Jacobian");
    const int nv = m_->nv;
    const mjtNum point[3] = {p_W.x(), p_W.y(), p_W.z()};
    mj_jac(m_, d_, jacp_->data(), jacr_->data(), point, body);
    if (J->cols() != nv) J->resize(6, nv);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < nv; ++c) {
        (*J)(r, c) = (*jacr_)[r * nv + c];
        (*J)(r + 3, c) = (*jacp_)[r * nv + c];
      }
  }

 private:
  void CheckBody(int body, const char* what) const {
    if (body < 0 || body >= m_->nbody)
      throw Error(std::string("ControlInput::") + what + ": body index " + std::to_string(body) +
                  " out of range [0, " + std::to_string(m_->nbody) + ")");
  }
  const mjModel* m_;
  mjData* d_;
  const ModelInfo* info_;
  std::vector<double>* jacp_;
  std::vector<double>* jacr_;
  double time_sec_;  // the controllers' clock (Simulation::ResetControllers)
};

JointInfo::Type JointType(int t) {
  switch (t) {
    case mjJNT_FREE:
      return JointInfo::Type::kFree;
    case mjJNT_BALL:
      return JointInfo::Type::kBall;
    case mjJNT_SLIDE:
      return JointInfo::Type::kSlide;
    default:
      return JointInfo::Type::kHinge;
  }
}

std::string NameOr(const mjModel* m, int type, int id) {
  const char* n = mj_id2name(m, type, id);
  return n ? std::string(n) : std::string();
}

// which MJCF shortcut actuator a's gain/bias/dynamics amount to (MuJoCo 2.2.2
// user_objects.cc mjCActuator and xml_native_reader.cc: <motor> gain [1] no bias,
// <position kp> gain [kp] bias [0 -kp 0], <velocity kv> gain [kv] bias [0 0 -kv]; a <general>
// with bias [0 -kp -kv] is a position servo with damping)
void ClassifyDrive(const mjModel* m, int a, ActuatorInfo* ai) {
  const mjtNum* g = m->actuator_gainprm + static_cast<size_t>(a) * mjNGAIN;
  const mjtNum* b = m->actuator_biasprm + static_cast<size_t>(a) * mjNBIAS;
  ai->drive = ActuatorDrive::kOther;
  if (m->actuator_dyntype[a] != mjDYN_NONE) {
    ai->drive_detail = "dyntype " + std::to_string(m->actuator_dyntype[a]) +
                       ": activation dynamics (integrator/filter/muscle/user)";
    return;
  }
  if (m->actuator_gaintype[a] != mjGAIN_FIXED) {
    ai->drive_detail = "gaintype " + std::to_string(m->actuator_gaintype[a]) + ": not fixed";
    return;
  }
  ai->gain = g[0];
  if (m->actuator_biastype[a] == mjBIAS_NONE) {
    ai->drive = ActuatorDrive::kMotor;
    return;
  }
  if (m->actuator_biastype[a] == mjBIAS_AFFINE && b[0] == 0) {
    if (b[1] < 0 && b[1] == -g[0] && b[2] <= 0) {
      ai->drive = ActuatorDrive::kPositionServo;
      ai->kp = g[0];
      ai->kv = -b[2];
      return;
    }
    if (b[1] == 0 && b[2] < 0 && b[2] == -g[0]) {
      ai->drive = ActuatorDrive::kVelocityServo;
      ai->kv = g[0];
      return;
    }
  }
  ai->drive_detail = "biastype " + std::to_string(m->actuator_biastype[a]) + ", biasprm " +
                     std::to_string(b[0]) + " " + std::to_string(b[1]) + " " +
                     std::to_string(b[2]) + " for gain " + std::to_string(g[0]);
}

ModelInfo BuildModelInfo(const mjModel* m) {
  ModelInfo info;
  info.nq = m->nq;
  info.nv = m->nv;
  info.nu = m->nu;
  info.nsensordata = m->nsensordata;
  info.timestep_sec = m->opt.timestep;
  for (int b = 0; b < m->nbody; ++b) {
    info.body_names.push_back(NameOr(m, mjOBJ_BODY, b));
    info.body_parent.push_back(b == 0 ? -1 : m->body_parentid[b]);
    info.body_mass.push_back(m->body_mass[b]);
    info.body_inertia.emplace_back(m->body_inertia[3 * b], m->body_inertia[3 * b + 1],
                                   m->body_inertia[3 * b + 2]);
    info.body_X_PB.push_back(PoseFromPosQuat(m->body_pos + 3 * b, m->body_quat + 4 * b));
    info.body_X_BI.push_back(PoseFromPosQuat(m->body_ipos + 3 * b, m->body_iquat + 4 * b));
  }
  for (int s = 0; s < m->nsite; ++s) {
    info.site_names.push_back(NameOr(m, mjOBJ_SITE, s));
    info.site_body.push_back(m->site_bodyid[s]);
    info.site_X_BS.push_back(PoseFromPosQuat(m->site_pos + 3 * s, m->site_quat + 4 * s));
  }
  for (int j = 0; j < m->njnt; ++j) {
    JointInfo ji;
    ji.name = NameOr(m, mjOBJ_JOINT, j);
    ji.type = JointType(m->jnt_type[j]);
    ji.qpos_adr = m->jnt_qposadr[j];
    ji.dof_adr = m->jnt_dofadr[j];
    ji.body = m->jnt_bodyid[j];
    ji.limited = m->jnt_limited[j] != 0;
    ji.range[0] = m->jnt_range[2 * j];
    ji.range[1] = m->jnt_range[2 * j + 1];
    ji.axis_B = Eigen::Vector3d(m->jnt_axis[3 * j], m->jnt_axis[3 * j + 1], m->jnt_axis[3 * j + 2]);
    ji.pos_B = Eigen::Vector3d(m->jnt_pos[3 * j], m->jnt_pos[3 * j + 1], m->jnt_pos[3 * j + 2]);
    ji.qpos0 = m->qpos0[m->jnt_qposadr[j]];
    info.joints.push_back(ji);
  }
  for (int a = 0; a < m->nu; ++a) {
    ActuatorInfo ai;
    ai.name = NameOr(m, mjOBJ_ACTUATOR, a);
    const int trn = m->actuator_trntype[a];
    ai.joint = (trn == mjTRN_JOINT || trn == mjTRN_JOINTINPARENT) ? m->actuator_trnid[2 * a] : -1;
    ai.site = trn == mjTRN_SITE ? m->actuator_trnid[2 * a] : -1;
    for (int k = 0; k < 6; ++k) ai.gear[k] = m->actuator_gear[6 * a + k];
    ai.ctrl_limited = m->actuator_ctrllimited[a] != 0;
    ai.ctrl_range[0] = m->actuator_ctrlrange[2 * a];
    ai.ctrl_range[1] = m->actuator_ctrlrange[2 * a + 1];
    ai.force_limited = m->actuator_forcelimited[a] != 0;
    ai.force_range[0] = m->actuator_forcerange[2 * a];
    ai.force_range[1] = m->actuator_forcerange[2 * a + 1];
    ClassifyDrive(m, a, &ai);
    info.actuators.push_back(ai);
  }
  for (int s = 0; s < m->nsensor; ++s)
    info.sensors.push_back({NameOr(m, mjOBJ_SENSOR, s), m->sensor_adr[s], m->sensor_dim[s]});
  for (int k = 0; k < m->nkey; ++k) {
    KeyInfo key;
    key.name = NameOr(m, mjOBJ_KEY, k);
    key.time_sec = m->key_time[k];
    key.qpos.assign(m->key_qpos + static_cast<size_t>(k) * m->nq,
                    m->key_qpos + static_cast<size_t>(k + 1) * m->nq);
    info.keys.push_back(std::move(key));
  }
  return info;
}

// true if any value is NaN or infinite (x * 0 is NaN exactly for those)
bool AnyNonFinite(const mjtNum* x, int n) {
  double acc = 0;
  for (int i = 0; i < n; ++i) acc += x[i] * 0.0;
  return acc != acc;
}

// body, camera and light poses for d's qpos and mocap poses: the first functions of
// mj_forward's position stage, in its order, so the poses are bit for bit mj_forward's.
void ComputePoses(const mjModel* m, mjData* d) {
  mj_kinematics(m, d);
  mj_comPos(m, d);
  mj_camlight(m, d);
}

// the runs of wrap points of `tendons` in `d` (after mj_tendon), split at pulleys (wrap_obj
// -2), as MuJoCo's mjv_addGeoms draws them.
void FillTendonPaths(const mjModel* m, const mjData* d, const std::vector<Tendon>& tendons,
                     std::vector<WorldSnapshot::TendonPath>* out) {
  out->clear();
  for (int i = 0; i < static_cast<int>(tendons.size()); ++i) {
    const int t = tendons[i].id;
    const int begin = d->ten_wrapadr[t], end = begin + d->ten_wrapnum[t];
    WorldSnapshot::TendonPath run;
    run.tendon = i;
    const auto flush = [&] {
      if (run.p_W.size() >= 2) out->push_back(run);
      run.p_W.clear();
    };
    for (int j = begin; j < end; ++j) {
      if (d->wrap_obj[j] == -2) {
        flush();
        continue;
      }
      run.p_W.emplace_back(d->wrap_xpos[3 * j], d->wrap_xpos[3 * j + 1], d->wrap_xpos[3 * j + 2]);
    }
    flush();
  }
}

}  // namespace

struct Simulation::Impl {
  struct Schedule {
    double rate_hz = 0;
    int64_t next = 0;  // index of the next update
  };

  std::string source;
  mjModel* m = nullptr;
  mjData* d = nullptr;
  // scratch data for snapshots: recomputing kinematics in `d` between steps would
  // change later contact results in the last bits (MuJoCo reuses some derived data)
  mjData* snap_d = nullptr;
  SceneDescription scene;
  ModelInfo info;
  std::vector<std::unique_ptr<Controller>> controllers;
  std::vector<Schedule> schedule;
  std::vector<char> due;
  // the step (steps) at which the due controllers already ran ahead of Step()
  // (RunDueControllers); -1 = none
  int64_t controllers_ran_at = -1;
  int64_t steps = 0;
  // the step of the last ResetControllers: the controllers' clock starts there
  int64_t episode_start = 0;
  int seen_warnings[mjNWARNING] = {};
  int warning_messages[mjNWARNING] = {};
  int64_t dropped_warnings = 0;
  std::vector<std::string> warnings;
  std::vector<int> qpos_joint;  // (nq) joint owning each qpos entry
  std::vector<double> jacp, jacr;
  std::vector<SensorDescription> sensor_info;
  struct MocapDriver {
    int mocap_id = -1;
    std::function<Pose(double)> X_WB;
  };
  std::vector<MocapDriver> mocap_drivers;
  bool failed = false;
  std::string failure;

  ~Impl() {
    if (snap_d) mj_deleteData(snap_d);
    if (d) mj_deleteData(d);
    if (m) mj_deleteModel(m);
  }

  std::string BodyLabel(int body) const {
    if (body < 0 || body >= m->nbody) return "body ?";
    const std::string& n = info.body_names[body];
    return n.empty() ? "body #" + std::to_string(body) + " (unnamed)" : "body '" + n + "'";
  }
  std::string JointLabel(int joint) const {
    if (joint < 0 || joint >= m->njnt) return "";
    const std::string& n = info.joints[joint].name;
    return n.empty() ? "joint #" + std::to_string(joint) : "joint '" + n + "'";
  }
  // "dof 3 (joint 'j') of body 'b'"
  std::string DofLabel(int dof) const {
    if (dof < 0 || dof >= m->nv) return "dof " + std::to_string(dof);
    return "dof " + std::to_string(dof) + " (" + JointLabel(m->dof_jntid[dof]) + ") of " +
           BodyLabel(m->dof_bodyid[dof]);
  }
  std::string QposLabel(int i) const {
    if (i < 0 || i >= m->nq) return "qpos[" + std::to_string(i) + "]";
    const int j = qpos_joint[i];
    return "qpos[" + std::to_string(i) + "] (" + JointLabel(j) + ") of " +
           BodyLabel(m->jnt_bodyid[j]);
  }
  std::string ActuatorLabel(int a) const {
    if (a < 0 || a >= m->nu) return "actuator " + std::to_string(a);
    const std::string& n = info.actuators[a].name;
    return n.empty() ? "actuator #" + std::to_string(a) : "actuator '" + n + "'";
  }
  std::string When(double t, int64_t step) const {
    char buf[96];
    std::snprintf(buf, sizeof(buf), "t = %.6g s (step %lld)", t, static_cast<long long>(step));
    return source + ": " + buf;
  }

  [[noreturn]] void Fail(double t, int64_t step, const std::string& what) {
    failed = true;
    d->time = t;  // MuJoCo may have reset the state: keep the time reached
    failure = When(t, step) + ": " + what;
    throw PhysicsError(failure);
  }

  // the controllers' clock at the current step (s)
  double ControlTime() const { return SimTimeOfStep(steps - episode_start, m->opt.timestep); }

  // sets due[i] for the controllers due at controllers' clock time t; true if any is
  bool MarkDue(double t) {
    const double tol = 1e-6 * m->opt.timestep;
    bool any = false;
    for (size_t i = 0; i < controllers.size(); ++i) {
      const Schedule& sc = schedule[i];
      due[i] = sc.rate_hz <= 0 || t + tol >= static_cast<double>(sc.next) / sc.rate_hz;
      any |= due[i] != 0;
    }
    return any;
  }

  // runs the due controllers at controllers' clock time tc (sim time t, for messages)
  void RunControllers(double tc, double t, int64_t step) {
    MujocoControlInput input(m, d, &info, &jacp, &jacr, tc);
    std::span<double> ctrl(d->ctrl, static_cast<size_t>(m->nu));
    const double tol = 1e-6 * m->opt.timestep;
    for (size_t i = 0; i < controllers.size(); ++i) {
      if (!due[i]) continue;
      controllers[i]->Compute(input, ctrl);
      for (std::string& w : controllers[i]->TakeWarnings())
        warnings.push_back(controllers[i]->label() + ": " + w);
      if (AnyNonFinite(d->ctrl, m->nu)) {
        for (int a = 0; a < m->nu; ++a)
          if (!std::isfinite(d->ctrl[a]))
            Fail(t, step,
                 "controller " + controllers[i]->label() + " wrote a non-finite ctrl (" +
                     std::to_string(d->ctrl[a]) + ") to " + ActuatorLabel(a) + " (joint " +
                     (info.actuators[a].joint >= 0
                          ? JointLabel(info.actuators[a].joint) + " of " +
                                BodyLabel(m->jnt_bodyid[info.actuators[a].joint])
                          : std::string("none")) +
                     ")");
      }
      Schedule& s = schedule[i];
      if (s.rate_hz > 0) s.next = static_cast<int64_t>(std::floor((tc + tol) * s.rate_hz)) + 1;
    }
  }

  // poses every driven mocap body for episode time t (ControlTime)
  void ApplyMocapDrivers(double t) {
    for (const MocapDriver& md : mocap_drivers) ApplyMocapDriver(md, t);
  }
  void ApplyMocapDriver(const MocapDriver& md, double t) {
    const Pose X = md.X_WB(t);
    const Eigen::Quaterniond q(X.linear());
    for (int k = 0; k < 3; ++k) d->mocap_pos[3 * md.mocap_id + k] = X.translation()[k];
    d->mocap_quat[4 * md.mocap_id + 0] = q.w();
    d->mocap_quat[4 * md.mocap_id + 1] = q.x();
    d->mocap_quat[4 * md.mocap_id + 2] = q.y();
    d->mocap_quat[4 * md.mocap_id + 3] = q.z();
  }

  void CheckWarnings(double t, int64_t step) {
    for (int w = 0; w < mjNWARNING; ++w) {
      const int n = d->warning[w].number;
      if (n == seen_warnings[w]) continue;
      seen_warnings[w] = n;
      const int info_i = d->warning[w].lastinfo;
      const char* kDiverged =
          "; MuJoCo reset the state. common causes: a timestep too large for stiff joints, "
          "gains or contacts; huge actuator gear or ctrl; tiny masses or inertias";
      switch (w) {
        case mjWARN_BADQPOS:
          Fail(t, step,
               "physics diverged: NaN, Inf or |x| > 1e10 in " + QposLabel(info_i) + kDiverged);
        case mjWARN_BADQVEL:
          Fail(t, step,
               "physics diverged: NaN, Inf or |x| > 1e10 in qvel at " + DofLabel(info_i) +
                   kDiverged);
        case mjWARN_BADQACC:
          Fail(t, step,
               "physics diverged: NaN, Inf or |x| > 1e10 in qacc at " + DofLabel(info_i) +
                   kDiverged);
        case mjWARN_BADCTRL:
          Fail(t, step, "NaN, Inf or |x| > 1e10 in ctrl of " + ActuatorLabel(info_i));
        default:
          break;
      }
      if (warning_messages[w] >= kMaxMessagesPerWarning) {
        ++dropped_warnings;
        continue;
      }
      ++warning_messages[w];
      std::string text = mju_warningText(w, info_i);
      if (w == mjWARN_INERTIA) text += " (" + DofLabel(info_i) + ")";
      warnings.push_back(When(t, step) + ": MuJoCo warning: " + text);
    }
  }

  void CheckFinite(double t, int64_t step) {
    const bool bad_pos = AnyNonFinite(d->qpos, m->nq);
    const bool bad_vel = AnyNonFinite(d->qvel, m->nv);
    const bool bad_acc = AnyNonFinite(d->qacc, m->nv);
    if (!(bad_pos || bad_vel || bad_acc)) return;
    for (int i = 0; i < m->nq; ++i)
      if (!std::isfinite(d->qpos[i])) Fail(t, step, "physics diverged: non-finite " + QposLabel(i));
    for (int i = 0; i < m->nv; ++i)
      if (!std::isfinite(d->qvel[i]))
        Fail(t, step, "physics diverged: non-finite qvel at " + DofLabel(i));
    for (int i = 0; i < m->nv; ++i)
      if (!std::isfinite(d->qacc[i]))
        Fail(t, step, "physics diverged: non-finite qacc at " + DofLabel(i));
  }
};

Simulation::Simulation(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Simulation::Simulation(Simulation&&) noexcept = default;
Simulation& Simulation::operator=(Simulation&&) noexcept = default;
Simulation::~Simulation() = default;

std::unique_ptr<Simulation::Impl> Simulation::LoadImpl(const std::string& loader_path,
                                                       const std::string* contents,
                                                       const std::string& source,
                                                       std::optional<double> timestep_sec) {
  if (timestep_sec && !(*timestep_sec >= kMinTimestepSec && *timestep_sec <= kMaxTimestepSec))
    throw ConfigError(source, 0, "timestep_sec",
                      "got " + FormatG(*timestep_sec) + "; expected seconds in [" +
                          FormatG(kMinTimestepSec) + ", " + FormatG(kMaxTimestepSec) + "]");
  InstallMujocoHandlers();
  auto impl = std::make_unique<Simulation::Impl>();
  impl->source = source;
  {
    std::lock_guard<std::mutex> lock(MujocoLoaderMutex());
    impl->m = LoadMujocoXmlLocked(loader_path, contents, source, &impl->warnings);
    FreeLastXmlLocked();  // the simulation never saves the XML back
  }
  mjModel* m = impl->m;
  if (timestep_sec) m->opt.timestep = *timestep_sec;
  // the model's own timestep (no override): 0 would never advance, < 0 runs backwards
  if (!(m->opt.timestep >= kMinTimestepSec && m->opt.timestep <= kMaxTimestepSec))
    throw ConfigError(source, 0, "option.timestep",
                      "the model's timestep is " + FormatG(m->opt.timestep) +
                          " s; expected seconds in [" + FormatG(kMinTimestepSec) + ", " +
                          FormatG(kMaxTimestepSec) + "]");
  // MuJoCo 4's multi-input/output actuators (<orientation>, a pid with several inputs) take
  // ctrlnum controls and give outnum forces; Penumbra's controllers, run logs, sensors and
  // bridges address one control and one force per actuator
  for (int a = 0; a < m->nactuator; ++a) {
    if (m->actuator_ctrlnum[a] == 1 && m->actuator_outnum[a] == 1) continue;
    const std::string name = NameOr(m, mjOBJ_ACTUATOR, a);
    throw ConfigError(source, 0, "actuator " + (name.empty() ? "#" + std::to_string(a) : name),
                      "the actuator takes " + std::to_string(m->actuator_ctrlnum[a]) +
                          " controls and gives " + std::to_string(m->actuator_outnum[a]) +
                          " forces (a MuJoCo 4 multi-input or multi-output actuator, e.g. "
                          "<orientation>); Penumbra supports one control and one force per "
                          "actuator: expected <motor>, <position>, <velocity>, <general> and the "
                          "other single-input actuators");
  }
  try {
    impl->d = mj_makeData(m);
    impl->snap_d = mj_makeData(m);
  } catch (const MujocoError& e) {
    throw PhysicsError(source + ": MuJoCo could not allocate the model's data: " + e.what());
  }
  if (!impl->d || !impl->snap_d)
    throw PhysicsError(source + ": MuJoCo could not allocate the model's data");
  mjData* d = impl->snap_d;
  // position-dependent quantities at qpos0 for the scene
  try {
    ComputePoses(m, d);
  } catch (const MujocoError& e) {
    throw PhysicsError(source + ": MuJoCo error at qpos0: " + e.what());
  }
  impl->scene = ExtractScene(m, d);
  impl->info = BuildModelInfo(m);
  impl->sensor_info = DescribeMujocoSensors(m);
  impl->qpos_joint.assign(m->nq, 0);
  for (int j = 0; j < m->njnt; ++j) {
    const int adr = m->jnt_qposadr[j];
    const int n = m->jnt_type[j] == mjJNT_FREE ? 7 : m->jnt_type[j] == mjJNT_BALL ? 4 : 1;
    for (int k = adr; k < adr + n && k < m->nq; ++k) impl->qpos_joint[k] = j;
  }
  impl->jacp.assign(3 * static_cast<size_t>(m->nv), 0.0);
  impl->jacr.assign(3 * static_cast<size_t>(m->nv), 0.0);
  for (int w = 0; w < mjNWARNING; ++w) impl->seen_warnings[w] = impl->d->warning[w].number;
  return impl;
}

Simulation Simulation::LoadFromFile(const std::string& mjcf_path,
                                    std::optional<double> timestep_sec) {
  return Simulation(LoadImpl(mjcf_path, nullptr, mjcf_path, timestep_sec));
}

Simulation Simulation::LoadFromString(const std::string& mjcf_xml,
                                      std::optional<double> timestep_sec,
                                      const std::string& asset_dir) {
  const std::filesystem::path dir =
      asset_dir.empty() ? std::filesystem::current_path() : std::filesystem::path(asset_dir);
  const std::string loader_path = (dir / "penumbra_inline_model.xml").string();
  return Simulation(LoadImpl(loader_path, &mjcf_xml, "<string>", timestep_sec));
}

void Simulation::AddController(std::unique_ptr<Controller> controller) {
  if (!controller) throw Error("Simulation::AddController: null controller");
  controller->Initialize(impl_->info);
  for (std::string& w : controller->TakeWarnings())
    impl_->warnings.push_back(controller->label() + ": " + w);
  const double rate = controller->rate_hz();
  if (!(std::isfinite(rate) && rate >= 0)) {
    const ControllerContext& c = controller->context();
    throw ConfigError(c.file, c.line, c.key,
                      "controller rate " + std::to_string(rate) + " Hz; expected a number >= 0");
  }
  Impl::Schedule s;
  s.rate_hz = rate;
  s.next = 0;
  // the first update runs at the first step at or after the current time
  if (rate > 0) {
    const double tol = 1e-6 * impl_->m->opt.timestep;
    s.next = static_cast<int64_t>(std::ceil((impl_->ControlTime() - tol) * rate));
  }
  impl_->controllers.push_back(std::move(controller));
  impl_->schedule.push_back(s);
  impl_->due.push_back(0);
}

void Simulation::AddMocapDriver(const std::string& body_name,
                                std::function<Pose(double time_sec)> X_WB) {
  const mjModel* m = impl_->m;
  const int body = mj_name2id(m, mjOBJ_BODY, body_name.c_str());
  if (body < 0)
    throw ConfigError("", 0, "mocap driver",
                      "no body named '" + body_name + "' in " + impl_->source +
                          "; expected the name of a mocap body");
  const int mocap = m->body_mocapid[body];
  if (mocap < 0)
    throw ConfigError("", 0, "mocap driver",
                      "body '" + body_name +
                          "' is not a mocap body; expected a body with "
                          "mocap=\"true\"");
  if (!X_WB) throw Error("Simulation::AddMocapDriver: empty pose function for '" + body_name + "'");
  impl_->mocap_drivers.push_back({mocap, std::move(X_WB)});
  impl_->ApplyMocapDrivers(impl_->ControlTime());
}

void Simulation::Step() {
  Impl& s = *impl_;
  if (s.failed) throw PhysicsError(s.failure + " (the simulation cannot continue)");
  const mjModel* m = s.m;
  mjData* d = s.d;
  const double t = d->time;
  const int64_t step = s.steps + 1;
  // controllers run ahead of the step (RunDueControllers) are not run again
  const double tc = s.ControlTime();
  const bool any_due = s.controllers_ran_at != s.steps && s.MarkDue(tc);
  s.controllers_ran_at = -1;
  try {
    if (any_due) {
      // position and velocity stages first, so controllers see a consistent state
      mj_step1(m, d);
      s.RunControllers(tc, t, step);
      if (m->opt.integrator == mjINT_RK4) {
        mj_step(m, d);
      } else {
        mj_step2(m, d);
      }
    } else {
      mj_step(m, d);
    }
  } catch (const MujocoError& e) {
    s.Fail(t, step, std::string("MuJoCo error: ") + e.what());
  } catch (const std::exception&) {
    throw;  // controllers' own errors pass through unchanged
  } catch (...) {
    // MuJoCo's compiler swaps in its own throwing handler while another thread loads a model
    s.Fail(t, step, "MuJoCo error (reported while another model was being loaded)");
  }
  s.CheckWarnings(t, step);
  s.CheckFinite(t, step);
  // time from the step count, not summed (SimTimeOfStep)
  s.steps = step;
  d->time = SimTimeOfStep(step, m->opt.timestep);
  if (!s.mocap_drivers.empty()) s.ApplyMocapDrivers(s.ControlTime());
}

SimState Simulation::GetState() const {
  SimState s;
  GetState(&s);
  return s;
}

void Simulation::GetState(SimState* out) const {
  const mjModel* m = impl_->m;
  const mjData* d = impl_->d;
  const StateDims dims = MujocoStateDims(m, static_cast<int64_t>(impl_->schedule.size()));
  out->step = impl_->steps;
  out->time_sec = d->time;
  ForEachStateField(
      [&](const StateFieldInfo& f, auto& v) {
        v.resize(StateFieldSize(f, dims));
        if constexpr (std::is_same_v<std::decay_t<decltype(v)>, std::vector<double>>) {
          ReadMujocoState(d, f.field, v);
        } else {
          for (size_t i = 0; i < v.size(); ++i) v[i] = impl_->schedule[i].next;
        }
      },
      *out);
}

std::vector<std::string> Simulation::MocapBodyNames() const {
  const mjModel* m = impl_->m;
  std::vector<std::string> names(m->nmocap);
  for (int b = 0; b < m->nbody; ++b) {
    const int id = m->body_mocapid[b];
    if (id >= 0) names[id] = mj_id2name(m, mjOBJ_BODY, b) ? mj_id2name(m, mjOBJ_BODY, b) : "";
  }
  return names;
}

bool Simulation::MocapDriven(int mocap_id) const {
  if (mocap_id < 0 || mocap_id >= impl_->m->nmocap)
    throw Error("mocap id " + std::to_string(mocap_id) + " outside [0, " +
                std::to_string(impl_->m->nmocap) + ")");
  for (const auto& md : impl_->mocap_drivers)
    if (md.mocap_id == mocap_id) return true;
  return false;
}

void Simulation::SetMocapPose(int mocap_id, const Pose& X_WB) {
  if (mocap_id < 0 || mocap_id >= impl_->m->nmocap)
    throw Error("mocap id " + std::to_string(mocap_id) + " outside [0, " +
                std::to_string(impl_->m->nmocap) + ")");
  if (!X_WB.matrix().allFinite()) throw Error("mocap pose is not finite");
  const Eigen::Quaterniond q = Eigen::Quaterniond(X_WB.linear()).normalized();
  mjData* d = impl_->d;
  for (int k = 0; k < 3; ++k) d->mocap_pos[3 * mocap_id + k] = X_WB.translation()[k];
  d->mocap_quat[4 * mocap_id + 0] = q.w();
  d->mocap_quat[4 * mocap_id + 1] = q.x();
  d->mocap_quat[4 * mocap_id + 2] = q.y();
  d->mocap_quat[4 * mocap_id + 3] = q.z();
}

void Simulation::SnapshotState(WorldSnapshot* out) const {
  GetState(out);
  out->episode_start_step = impl_->episode_start;
}

void Simulation::SetState(const SimState& s) {
  Impl& impl = *impl_;
  const mjModel* m = impl.m;
  mjData* d = impl.d;
  const std::string bad =
      StateMismatch(s, MujocoStateDims(m, static_cast<int64_t>(impl.schedule.size())));
  if (!bad.empty()) throw Error(impl.source + ": SetState: " + bad + " for this model");
  if (s.step < 0 || s.time_sec != SimTimeOfStep(s.step, m->opt.timestep))
    throw Error(impl.source + ": SetState: time_sec " + FormatG(s.time_sec) +
                " is not the time of step " + std::to_string(s.step) + " (" +
                FormatG(SimTimeOfStep(s.step, m->opt.timestep)) + " s)");
  d->time = s.time_sec;
  ForEachStateField(
      [&](const StateFieldInfo& f, const auto& v) {
        if constexpr (std::is_same_v<std::decay_t<decltype(v)>, std::vector<double>>) {
          WriteMujocoState(d, f.field, v);
        } else {
          for (size_t i = 0; i < v.size(); ++i) impl.schedule[i].next = v[i];
        }
      },
      s);
  impl.steps = s.step;
  if (impl.steps < impl.episode_start) impl.episode_start = 0;
  impl.controllers_ran_at = -1;
  impl.failed = false;
  impl.failure.clear();
}

void Simulation::ApplyMocapDrivers(std::span<const int> mocap_ids) {
  Impl& impl = *impl_;
  const double t = impl.ControlTime();
  for (const int id : mocap_ids) {
    if (id < 0 || id >= impl.m->nmocap)
      throw Error(impl.source + ": ApplyMocapDrivers: mocap id " + std::to_string(id) +
                  " is outside [0, " + std::to_string(impl.m->nmocap) + ")");
    for (const Impl::MocapDriver& md : impl.mocap_drivers)
      if (md.mocap_id == id) impl.ApplyMocapDriver(md, t);
  }
}

void Simulation::ApplyKeyframe(const std::string& key, const std::string& prefix,
                               const std::string& error_key) {
  const mjModel* m = impl_->m;
  mjData* d = impl_->d;
  const int k = mj_name2id(m, mjOBJ_KEY, key.c_str());
  if (k < 0) {
    std::string keys;
    for (int i = 0; i < m->nkey; ++i) {
      const std::string name = NameOr(m, mjOBJ_KEY, i);
      if (name.rfind(prefix, 0) == 0)
        keys += (keys.empty() ? "" : ", ") + name.substr(prefix.size());
    }
    throw ConfigError(
        "", 0, error_key,
        "no keyframe '" + key.substr(std::min(key.size(), prefix.size())) + "' in model '" +
            prefix.substr(0, prefix.size() - 1) +
            "'; expected one of its <key> names: " + (keys.empty() ? "(it has none)" : keys));
  }
  // an element is the model's when its name carries the prefix; an unnamed one (Menagerie's
  // `<freejoint/>`, an unnamed actuator) when what it belongs to is: a body by its nearest named
  // ancestor, a joint by its body, an actuator by its transmission's target
  const auto named = [&](mjtObj type, int id) -> std::optional<bool> {
    const char* name = mj_id2name(m, type, id);
    if (name == nullptr || *name == '\0') return std::nullopt;
    return std::string(name).rfind(prefix, 0) == 0;
  };
  const auto body_mine = [&](int b) {
    for (; b > 0; b = m->body_parentid[b])
      if (const auto own = named(mjOBJ_BODY, b)) return *own;
    return false;
  };
  const auto joint_mine = [&](int j) {
    const auto own = named(mjOBJ_JOINT, j);
    return own ? *own : body_mine(m->jnt_bodyid[j]);
  };
  const auto mine = [&](mjtObj type, int id) {
    if (const auto own = named(type, id)) return *own;
    if (type == mjOBJ_BODY) return body_mine(id);
    if (type != mjOBJ_ACTUATOR) return false;
    const int target = m->actuator_trnid[2 * id];
    switch (m->actuator_trntype[id]) {
      case mjTRN_JOINT:
      case mjTRN_JOINTINPARENT:
        return joint_mine(target);
      case mjTRN_SITE:
        return body_mine(m->site_bodyid[target]);
      case mjTRN_BODY:
        return body_mine(target);
      case mjTRN_TENDON:
        return named(mjOBJ_TENDON, target).value_or(false);
      default:
        return false;
    }
  };
  for (int j = 0; j < m->njnt; ++j) {
    if (!joint_mine(j)) continue;
    const int type = m->jnt_type[j];
    const int nq = type == mjJNT_FREE ? 7 : type == mjJNT_BALL ? 4 : 1;
    const int nv = type == mjJNT_FREE ? 6 : type == mjJNT_BALL ? 3 : 1;
    for (int i = 0; i < nq; ++i) {
      const int a = m->jnt_qposadr[j] + i;
      d->qpos[a] = m->key_qpos[static_cast<size_t>(k) * m->nq + a];
    }
    for (int i = 0; i < nv; ++i) {
      const int a = m->jnt_dofadr[j] + i;
      d->qvel[a] = m->key_qvel[static_cast<size_t>(k) * m->nv + a];
    }
  }
  for (int a = 0; a < m->nu; ++a) {
    if (!mine(mjOBJ_ACTUATOR, a)) continue;
    d->ctrl[a] = m->key_ctrl[static_cast<size_t>(k) * m->nu + a];
    for (int i = 0; i < m->actuator_actnum[a]; ++i) {
      const int act = m->actuator_actadr[a] + i;
      d->act[act] = m->key_act[static_cast<size_t>(k) * m->na + act];
    }
  }
  for (int b = 0; b < m->nbody; ++b) {
    const int mocap = m->body_mocapid[b];
    if (mocap < 0 || !mine(mjOBJ_BODY, b)) continue;
    for (int i = 0; i < 3; ++i)
      d->mocap_pos[3 * mocap + i] =
          m->key_mpos[static_cast<size_t>(k) * 3 * m->nmocap + 3 * mocap + i];
    for (int i = 0; i < 4; ++i)
      d->mocap_quat[4 * mocap + i] =
          m->key_mquat[static_cast<size_t>(k) * 4 * m->nmocap + 4 * mocap + i];
  }
  mj_forward(m, d);
}

void Simulation::RunDueControllers() {
  Impl& s = *impl_;
  if (s.failed) throw PhysicsError(s.failure + " (the simulation cannot continue)");
  if (s.controllers_ran_at == s.steps) return;
  const double t = s.d->time;
  const int64_t step = s.steps + 1;
  const double tc = s.ControlTime();
  if (!s.MarkDue(tc)) return;
  try {
    mj_step1(s.m, s.d);
    s.RunControllers(tc, t, step);
  } catch (const MujocoError& e) {
    s.Fail(t, step, std::string("MuJoCo error: ") + e.what());
  } catch (const std::exception&) {
    throw;
  } catch (...) {
    s.Fail(t, step, "MuJoCo error (reported while another model was being loaded)");
  }
  s.controllers_ran_at = s.steps;
}

void Simulation::ResetControllers() {
  Impl& s = *impl_;
  for (const auto& c : s.controllers) {
    c->Reset();
    for (std::string& w : c->TakeWarnings()) s.warnings.push_back(c->label() + ": " + w);
  }
  s.episode_start = s.steps;
  for (Impl::Schedule& sc : s.schedule) sc.next = 0;
  s.controllers_ran_at = -1;
}

int64_t Simulation::controller_episode_start() const { return impl_->episode_start; }

double Simulation::time() const { return impl_->d->time; }
int64_t Simulation::step_count() const { return impl_->steps; }
double Simulation::timestep() const { return impl_->m->opt.timestep; }

WorldSnapshot Simulation::Snapshot(SnapshotContent content) const {
  WorldSnapshot out;
  Snapshot(&out, content);
  return out;
}

void Simulation::Snapshot(WorldSnapshot* out, SnapshotContent content) const {
  const mjModel* m = impl_->m;
  const mjData* live = impl_->d;
  mjData* d = impl_->snap_d;
  try {
    CopyStateForForward(m, live, d);
    if (content == SnapshotContent::kFull) {
      // the whole forward pass: sensors, body velocities and contacts for this instant
      // (mj_step's own sensordata belong to the previous step)
      mj_forward(m, d);
    } else {
      ComputePoses(m, d);
      // the tendons' wrap points (mj_forward computes them for kFull)
      if (!impl_->scene.tendons.empty()) mj_tendon(m, d);
    }
  } catch (const MujocoError& e) {
    throw PhysicsError(impl_->When(live->time, impl_->steps) + ": MuJoCo error: " + e.what());
  }
  out->time_sec = live->time;
  out->step = impl_->steps;
  out->episode_start_step = impl_->episode_start;
  out->X_WB.resize(m->nbody);
  for (int b = 0; b < m->nbody; ++b)
    out->X_WB[b] = PoseFromPosQuat(d->xpos + 3 * b, d->xquat + 4 * b);
  out->X_W_mjcam.resize(m->ncam);
  for (int c = 0; c < m->ncam; ++c) {
    Pose X = Pose::Identity();
    X.linear() =
        Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(d->cam_xmat + 9 * c);
    X.translation() =
        Eigen::Vector3d(d->cam_xpos[3 * c], d->cam_xpos[3 * c + 1], d->cam_xpos[3 * c + 2]);
    out->X_W_mjcam[c] = X;
  }
  out->light_position_W.resize(m->nlight);
  out->light_direction_W.resize(m->nlight);
  for (int l = 0; l < m->nlight; ++l) {
    out->light_position_W[l] =
        Eigen::Vector3d(d->light_xpos[3 * l], d->light_xpos[3 * l + 1], d->light_xpos[3 * l + 2]);
    Eigen::Vector3d dir(d->light_xdir[3 * l], d->light_xdir[3 * l + 1], d->light_xdir[3 * l + 2]);
    out->light_direction_W[l] = dir.norm() > 0 ? dir.normalized() : Eigen::Vector3d(0, 0, -1);
  }
  FillTendonPaths(m, d, impl_->scene.tendons, &out->tendon_paths);
  SnapshotState(out);
  out->tracking_error.clear();
  if (content == SnapshotContent::kFull) {
    FillSensorGroundTruth(m, d, out);
    for (const auto& c : impl_->controllers) c->AppendTrackingError(&out->tracking_error);
  } else {
    out->sensordata.clear();
    out->V_WB.clear();
    out->contacts.clear();
    out->qfrc_actuator.clear();
  }
}

const std::vector<SensorDescription>& Simulation::sensor_info() const { return impl_->sensor_info; }

const SceneDescription& Simulation::scene() const { return impl_->scene; }
const ModelInfo& Simulation::model_info() const { return impl_->info; }

std::vector<std::string> Simulation::TakeWarnings() {
  std::vector<std::string> out = std::move(impl_->warnings);
  impl_->warnings.clear();
  if (impl_->dropped_warnings > 0) {
    out.push_back(impl_->source + ": " + std::to_string(impl_->dropped_warnings) +
                  " more MuJoCo warnings of the same kinds (not listed)");
    impl_->dropped_warnings = 0;
  }
  return out;
}

std::span<const double> Simulation::qpos() const {
  return {impl_->d->qpos, static_cast<size_t>(impl_->m->nq)};
}
std::span<const double> Simulation::qvel() const {
  return {impl_->d->qvel, static_cast<size_t>(impl_->m->nv)};
}
std::span<double> Simulation::ctrl() { return {impl_->d->ctrl, static_cast<size_t>(impl_->m->nu)}; }
const std::string& Simulation::source() const { return impl_->source; }
int Simulation::num_controllers() const { return static_cast<int>(impl_->controllers.size()); }
const Controller& Simulation::controller(int i) const { return *impl_->controllers.at(i); }

Controller& Simulation::mutable_controller(int i) { return *impl_->controllers.at(i); }

}  // namespace penumbra
