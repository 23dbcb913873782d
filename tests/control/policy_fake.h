#pragma once
// a hand-made 12-joint quadruped model (prefixed "q/") and a fake ControlInput over it, for
// unit tests of the policy controller's observation and action paths without MuJoCo.
//
// bodies: world, q/trunk (free joint: qpos 0..6, qvel 0..5), q/leg0 .. q/leg11 (one hinge
// each); joints q/free, q/j0 .. q/j11 (qpos 7 + i, qvel 6 + i); actuators named like their
// joints: motors with gear 1 (gear 2 on j5), ctrlrange +-100; sensors q/touch0 .. q/touch3
// (1 value each, sensordata 0..3) and q/gyro (3 values, sensordata 4..6).

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "penumbra/config/yaml_document.h"
#include "penumbra/control/control_input.h"
#include "penumbra/control/controller_factory.h"
#include "penumbra/control/model_info.h"

namespace penumbra::policy_fake {

inline ModelInfo QuadModel(bool position_servos = false) {
  ModelInfo m;
  m.nq = 7 + 12;
  m.nv = 6 + 12;
  m.nu = 12;
  m.nsensordata = 7;
  m.timestep_sec = 0.005;
  m.body_names = {"world", "q/trunk"};
  m.body_parent = {-1, 0};
  JointInfo free;
  free.name = "q/free";
  free.type = JointInfo::Type::kFree;
  free.body = 1;
  m.joints.push_back(free);
  for (int i = 0; i < 12; ++i) {
    m.body_names.push_back("q/leg" + std::to_string(i));
    m.body_parent.push_back(1);
    JointInfo j;
    j.name = "q/j" + std::to_string(i);
    j.qpos_adr = 7 + i;
    j.dof_adr = 6 + i;
    j.body = 2 + i;
    m.joints.push_back(j);
    ActuatorInfo a;
    a.name = "q/j" + std::to_string(i);
    a.joint = 1 + i;
    a.ctrl_limited = true;
    a.ctrl_range[0] = -100;
    a.ctrl_range[1] = 100;
    a.gear[0] = i == 5 ? 2 : 1;
    if (position_servos) {
      a.drive = ActuatorDrive::kPositionServo;
      a.kp = 30;
      a.gain = 30;
      a.ctrl_range[0] = -4;
      a.ctrl_range[1] = 4;
    }
    m.actuators.push_back(a);
  }
  for (int k = 0; k < 4; ++k) m.sensors.push_back({"q/touch" + std::to_string(k), k, 1});
  m.sensors.push_back({"q/gyro", 4, 3});
  return m;
}

// the trunk's pose and twist, joint state and sensor values are set by the test
class QuadInput final : public ControlInput {
 public:
  explicit QuadInput(const ModelInfo& m)
      : model_(m), q_(m.nq, 0.0), qd_(m.nv, 0.0), sd_(m.nsensordata, 0.0) {}
  double time_sec() const override { return t_; }
  const ModelInfo& model() const override { return model_; }
  std::span<const double> qpos() const override { return q_; }
  std::span<const double> qvel() const override { return qd_; }
  std::span<const double> sensordata() const override { return sd_; }
  Pose X_WB(int body) const override { return body == 1 ? X_WB_ : Pose::Identity(); }
  Twist V_WB(int body) const override { return body == 1 ? V_WB_ : Twist::Zero(); }
  void Jacobian(int, const Eigen::Vector3d&,
                Eigen::Matrix<double, 6, Eigen::Dynamic>* J) const override {
    J->setZero(6, model_.nv);
  }

  const ModelInfo& model_;
  double t_ = 0;
  std::vector<double> q_, qd_, sd_;
  Pose X_WB_ = Pose::Identity();
  Twist V_WB_ = Twist::Zero();
};

// the controller built by the factory for robot "q" from a YAML body (world file in the
// source tree's tests/control/fixtures folder, so `model:` paths are relative to it)
inline std::unique_ptr<Controller> MakePolicy(const std::string& body) {
  ControllerConfig cfg;
  cfg.type = "policy";
  cfg.line = 7;
  cfg.params = ParseYaml("type: policy\n" + body);
  return MakeController(cfg, "q", PENUMBRA_SOURCE_DIR "/tests/control/fixtures/world.yaml");
}

}  // namespace penumbra::policy_fake
