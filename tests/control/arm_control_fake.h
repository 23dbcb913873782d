#pragma once
// a hand-made model of a 7-joint arm (hinges 0..6 plus a slide finger with a position
// actuator on a tendon, prefixed "a/") and a fake ControlInput over it, for unit tests of
// the joint servo and the arm controllers without MuJoCo.

#include <vector>

#include "penumbra/config/yaml_document.h"
#include "penumbra/control/control_input.h"
#include "penumbra/control/controller_factory.h"
#include "penumbra/control/model_info.h"

namespace penumbra::arm_fake {

// bodies: world, a/base, a/link1 .. a/link7 (a chain), joints a/j1 .. a/j7 (hinges, ranges
// [-2, 2] except j4 [-3, -0.1]), a/finger (slide [0, 0.04]); actuators a/m1 .. a/m7 (motors on
// the hinges, ctrlrange +-50, gear 2 on m7), a/grip (tendon: no joint, ctrlrange [0, 0.04]);
// site a/ee on link7; keys a/home and a/bent.
inline ModelInfo ArmModel() {
  ModelInfo m;
  m.nq = m.nv = 8;
  m.nu = 8;
  m.body_names = {"world", "a/base"};
  m.body_parent = {-1, 0};
  for (int i = 1; i <= 7; ++i) {
    m.body_names.push_back("a/link" + std::to_string(i));
    m.body_parent.push_back(i);
  }
  for (int i = 0; i < 7; ++i) {
    JointInfo j;
    j.name = "a/j" + std::to_string(i + 1);
    j.qpos_adr = j.dof_adr = i;
    j.body = i + 2;
    j.limited = true;
    j.range[0] = i == 3 ? -3 : -2;
    j.range[1] = i == 3 ? -0.1 : 2;
    m.joints.push_back(j);
    ActuatorInfo a;
    a.name = "a/m" + std::to_string(i + 1);
    a.joint = i;
    a.ctrl_limited = true;
    a.ctrl_range[0] = -50;
    a.ctrl_range[1] = 50;
    a.gear[0] = i == 6 ? 2 : 1;
    m.actuators.push_back(a);
  }
  JointInfo f;
  f.name = "a/finger";
  f.type = JointInfo::Type::kSlide;
  f.qpos_adr = f.dof_adr = 7;
  f.body = 8;
  f.limited = true;
  f.range[1] = 0.04;
  m.joints.push_back(f);
  ActuatorInfo g;
  g.name = "a/grip";
  g.ctrl_limited = true;
  g.ctrl_range[1] = 0.04;
  m.actuators.push_back(g);
  m.site_names = {"a/ee"};
  m.site_body = {8};
  m.site_X_BS = {Pose::Identity()};
  KeyInfo home{"a/home", 0, {0, -0.5, 0, -2, 0, 1.5, 0.5, 0.04}};
  KeyInfo bent{"a/bent", 0, {1, -1, 0.5, -2.5, 0.2, 1, 0, 0}};
  m.keys = {home, bent};
  return m;
}

// state set by the test; the site's body pose is X_ee, Jacobian zero unless set
class FakeInput final : public ControlInput {
 public:
  explicit FakeInput(const ModelInfo& m)
      : model_(m), q_(m.nq, 0.0), qd_(m.nv, 0.0), bias_(m.nv, 0.0) {}
  double time_sec() const override { return t_; }
  const ModelInfo& model() const override { return model_; }
  std::span<const double> qpos() const override { return q_; }
  std::span<const double> qvel() const override { return qd_; }
  std::span<const double> sensordata() const override { return {}; }
  std::span<const double> qfrc_bias() const override {
    return with_bias_ ? std::span<const double>(bias_) : std::span<const double>();
  }
  Pose X_WB(int body) const override { return body == 8 ? X_ee_ : Pose::Identity(); }
  Twist V_WB(int) const override { return Twist::Zero(); }
  void Jacobian(int, const Eigen::Vector3d&,
                Eigen::Matrix<double, 6, Eigen::Dynamic>* J) const override {
    if (J->cols() != model_.nv) J->resize(6, model_.nv);
    J->setZero();
    if (jacobian_.cols() == model_.nv) *J = jacobian_;
  }

  const ModelInfo& model_;
  double t_ = 0;
  std::vector<double> q_, qd_, bias_;
  bool with_bias_ = true;
  Pose X_ee_ = Pose::Identity();
  Eigen::Matrix<double, 6, Eigen::Dynamic> jacobian_;
};

inline ControllerConfig Block(const std::string& type, const std::string& body) {
  ControllerConfig cfg;
  cfg.type = type;
  cfg.line = 30;
  cfg.params = ParseYaml("type: " + type + "\n" + body);
  return cfg;
}

inline const char* kServo =
    "joints: [j1, j2, j3, j4, j5, j6, j7]\n"
    "actuators: [m1, m2, m3, m4, m5, m6, m7]\n";

// the controller built by the factory for robot "a" and initialised against ArmModel()
template <typename T>
std::unique_ptr<T> Make(const ModelInfo& m, const std::string& type, const std::string& body) {
  std::unique_ptr<Controller> c = MakeController(Block(type, body), "a", "world.yaml");
  T* typed = dynamic_cast<T*>(c.get());
  if (!typed) return nullptr;
  c.release();
  std::unique_ptr<T> out(typed);
  out->Initialize(m);
  return out;
}

}  // namespace penumbra::arm_fake
